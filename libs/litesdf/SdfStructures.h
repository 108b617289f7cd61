// Sampled signed distance fields, in plain data a translated class can upload as it is:
//   - SdfGrid: a dense grid of N^3 samples with trilinear interpolation, the baseline;
//   - SdfSVS (sparse voxel set): only the voxels the surface crosses, each with its 8 corner
//     distances, quantised to 1 or 2 bytes relative to the voxel's diagonal, or kept as 4-byte floats;
//   - SdfSBS (sparse brick set): bricks of b^3 voxels with their (b+1)^3 values, 1, 2 or 4 bytes each.
// All live in a cube [boxMin, boxMin + boxSize]^3 split into 2^depth voxels per axis. Each says how
// many bytes it takes. SdfBuild.cpp builds them from an analytic SDF (SdfAnalytic.h).
#pragma once
#include "SdfAnalytic.h"
#include "SdfVoxel.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace litesdf {

// Counts from a build: how much the sign test saves over keeping every voxel the surface may cross.
struct SdfBuildStats {
  uint64_t cellsVisited = 0;     // octree cells whose distance was evaluated
  uint64_t voxelsCrossable = 0;  // finest voxels within a half diagonal of the surface
  uint64_t voxelsKept = 0;       // of those, voxels whose trilinear interpolant changes sign
  double milliseconds = 0.0;
};

struct SdfGrid {
  uint32_t samples = 0;  // per axis: (samples - 1)^3 cells
  float3 boxMin = float3(0.0f, 0.0f, 0.0f);
  float boxSize = 0.0f;
  std::vector<float> values;  // x fastest, then y, then z

  float CellSize() const { return boxSize / float(samples - 1); }
  float Value(uint32_t x, uint32_t y, uint32_t z) const { return values[(size_t(z) * samples + y) * samples + x]; }
  // The trilinear interpolation at p, clamped into the box.
  float Sample(float3 p) const;
  size_t Bytes() const { return values.size() * sizeof(float); }
};

// Quantisation of a corner value relative to the voxel's diagonal: codes 0..2^(8 bytes)-1 cover
// [-diagonal, +diagonal]; 4 bytes keep the float. The round trip errs by at most half a step,
// diagonal / (2^(8 bytes) - 1).
uint32_t QuantiseDistance(float d, float diagonal, uint32_t bytesPerValue);
float DequantiseDistance(uint32_t code, float diagonal, uint32_t bytesPerValue);

// Values packed `bytesPerValue` at a time into 32-bit words, little end first.
void PackValue(std::vector<uint32_t>& words, size_t index, uint32_t code, uint32_t bytesPerValue);
uint32_t UnpackValue(const std::vector<uint32_t>& words, size_t index, uint32_t bytesPerValue);

struct SdfSVS {
  float3 boxMin = float3(0.0f, 0.0f, 0.0f);
  float boxSize = 0.0f;
  uint32_t depth = 0;          // 2^depth voxels per axis, depth <= 10
  uint32_t bytesPerValue = 2;  // 1, 2 or 4
  std::vector<uint32_t> coords;  // per voxel: x | y << 10 | z << 20
  std::vector<uint32_t> values;  // 8 values per voxel, packed; corner (x, y, z) at x + 2y + 4z

  float VoxelSize() const { return boxSize / float(1u << depth); }
  size_t VoxelCount() const { return coords.size(); }
  float3 VoxelMin(size_t i) const;
  VoxelValues Values(size_t i) const;
  size_t Bytes() const { return (coords.size() + values.size()) * sizeof(uint32_t); }
};

struct SdfSBS {
  float3 boxMin = float3(0.0f, 0.0f, 0.0f);
  float boxSize = 0.0f;
  uint32_t depth = 0;          // 2^depth voxels per axis, depth <= 10
  uint32_t brickSize = 4;      // voxels per brick edge, a power of 2 no larger than 2^depth
  uint32_t bytesPerValue = 1;  // 1, 2 or 4
  std::vector<uint32_t> coords;  // per brick: its first voxel, x | y << 10 | z << 20
  std::vector<uint32_t> values;  // (brickSize + 1)^3 values per brick, packed, each brick from a new word

  float VoxelSize() const { return boxSize / float(1u << depth); }
  uint32_t ValuesPerBrick() const { return (brickSize + 1) * (brickSize + 1) * (brickSize + 1); }
  uint32_t WordsPerBrick() const { return (ValuesPerBrick() * bytesPerValue + 3) / 4; }
  size_t BrickCount() const { return coords.size(); }
  float3 BrickMin(size_t brick) const;
  // The voxel (x, y, z) of a brick, 0 <= x, y, z < brickSize.
  VoxelValues Values(size_t brick, uint32_t x, uint32_t y, uint32_t z) const;
  size_t Bytes() const { return (coords.size() + values.size()) * sizeof(uint32_t); }
};

// What makes a structure unusable (no samples, a depth over 10, a value size other than 1, 2 or 4,
// values that do not match the counts, a cube that is empty or not finite), or "" when it is sound.
std::string Problem(const SdfGrid& grid);
std::string Problem(const SdfSVS& svs);
std::string Problem(const SdfSBS& sbs);

// Builders from an analytic SDF over the cube [boxMin, boxMin + boxSize]^3. They evaluate it on
// all cores (OpenMP): `sdf.Distance` is called from several threads at once. The result does not
// depend on the number of threads.
SdfGrid BuildGrid(const ISdf& sdf, float3 boxMin, float boxSize, uint32_t samples);
// Top-down: an octree cell is split only when the surface may cross it (|distance at its centre| <=
// half its diagonal); a finest voxel is kept only when its trilinear interpolant changes sign (the
// interpolant's extremes are at the corners).
SdfSVS BuildSVS(const ISdf& sdf, float3 boxMin, float boxSize, uint32_t depth, uint32_t bytesPerValue, SdfBuildStats* stats = nullptr);
// The deepest SVS, up to `maxDepth`, that fits in `maxBytes`: depths are built from coarse to fine
// (each costs about 4x the one before) until the next would not fit. Throws when even depth 1 does
// not fit.
SdfSVS BuildSVSWithinBudget(const ISdf& sdf, float3 boxMin, float boxSize, uint32_t maxDepth, uint32_t bytesPerValue, size_t maxBytes,
                            SdfBuildStats* stats = nullptr);
// As BuildSVS, keeping the bricks that hold at least one voxel whose interpolant changes sign.
SdfSBS BuildSBS(const ISdf& sdf, float3 boxMin, float boxSize, uint32_t depth, uint32_t brickSize, uint32_t bytesPerValue,
                SdfBuildStats* stats = nullptr);

}  // namespace litesdf
