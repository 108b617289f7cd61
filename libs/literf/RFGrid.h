// A ReLU field (Karnewar et al. 2022): a regular grid of vertices over a box, each holding a raw
// density and, per colour channel, the coefficients of spherical harmonics of degree 0 to 2. At a
// point, every value is interpolated trilinearly; density = ReLU(raw) * densityScale and colour =
// sigmoid(SH(direction) . coefficients). This is the host side: the model, its file format and the
// grid operations of training (upsampling, pruning, the occupied cells). RFSample.h evaluates it.
#pragma once
#include "LiteMath.h"

#include <cstdint>
#include <string>
#include <vector>

namespace literf {

// Spherical harmonics coefficients per colour channel for a degree (0, 1 or 2): 1, 4 or 9.
inline int ShCoefficients(int degree) { return (degree + 1) * (degree + 1); }

struct RFGrid
{
  int cells = 0;     // cells per axis; the grid has cells + 1 vertices per axis
  int shDegree = 0;  // 0, 1 or 2
  LiteMath::float3 boxMin = LiteMath::float3(-1.5f, -1.5f, -1.5f), boxMax = LiteMath::float3(1.5f, 1.5f, 1.5f);
  float densityScale = 100.0f;  // density = ReLU(raw) * densityScale
  // Per vertex (x fastest, then y, then z), Channels() floats: raw density, then the red, green and
  // blue SH coefficients (ShCoefficients(shDegree) each).
  std::vector<float> values;

  int Vertices() const { return cells + 1; }
  int Channels() const { return 1 + 3 * ShCoefficients(shDegree); }
  size_t Bytes() const { return values.size() * sizeof(float); }
};

// A grid of `cells`³ cells with every density at `density` and every colour coefficient 0 (grey).
RFGrid MakeGrid(int cells, int shDegree, float density, LiteMath::float3 boxMin, LiteMath::float3 boxMax);

// The same field on a grid of `cells` cells: every vertex takes the old grid's trilinear value there
// (coarse-to-fine training doubles the cells between stages).
RFGrid Upsample(const RFGrid& grid, int cells);

// Whether a cell can hold density: ReLU of a trilinear value is 0 in the whole cell exactly when
// none of its 8 corners has a positive raw density. Index: x + cells * (y + cells * z).
std::vector<uint8_t> OccupiedCells(const RFGrid& grid);

// Sets the raw density of every vertex all of whose cells are negligible (the largest opacity a ray
// could collect crossing one, 1 - exp(-max density * cell diagonal), below `alphaThreshold`) to at
// most 0, which empties those cells exactly. Returns the number of occupied cells left.
size_t Prune(RFGrid& grid, float alphaThreshold);

// The model file: "CRTRF" and a version, then the grid. Reading checks both and the sizes, and
// throws std::runtime_error with the path and the reason.
constexpr uint32_t kModelVersion = 1;
void SaveModel(const std::string& path, const RFGrid& grid);
RFGrid LoadModel(const std::string& path);

// Why a grid cannot be used (a degree outside 0..2, no cells, values of the wrong count, an empty
// box, a density scale that is not positive), or "".
std::string Problem(const RFGrid& grid);

}  // namespace literf
