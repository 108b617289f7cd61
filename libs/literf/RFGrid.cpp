#include "RFGrid.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace literf {

using LiteMath::float3;

RFGrid MakeGrid(int cells, int shDegree, float density, float3 boxMin, float3 boxMax)
{
  RFGrid g;
  g.cells = cells;
  g.shDegree = shDegree;
  g.boxMin = boxMin;
  g.boxMax = boxMax;
  const size_t vertices = size_t(cells + 1) * size_t(cells + 1) * size_t(cells + 1);
  g.values.assign(vertices * size_t(g.Channels()), 0.0f);
  for (size_t v = 0; v < vertices; ++v)
    g.values[v * size_t(g.Channels())] = density;
  return g;
}

RFGrid Upsample(const RFGrid& grid, int cells)
{
  RFGrid out = grid;
  out.cells = cells;
  const int n = cells + 1, c = grid.Channels(), old = grid.Vertices();
  out.values.assign(size_t(n) * n * n * c, 0.0f);
  auto at = [&](int x, int y, int z) { return &grid.values[(size_t(x) + size_t(old) * (size_t(y) + size_t(old) * size_t(z))) * c]; };
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
      {
        // The vertex in the old grid's cell coordinates, its cell and the weights inside it.
        const float u[3] = {float(x) * grid.cells / cells, float(y) * grid.cells / cells, float(z) * grid.cells / cells};
        int i[3];
        float f[3];
        for (int a = 0; a < 3; ++a)
        {
          i[a] = std::min(int(u[a]), grid.cells - 1);
          f[a] = u[a] - float(i[a]);
        }
        float* dst = &out.values[(size_t(x) + size_t(n) * (size_t(y) + size_t(n) * size_t(z))) * c];
        for (int corner = 0; corner < 8; ++corner)
        {
          const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
          const float w = (dx ? f[0] : 1.0f - f[0]) * (dy ? f[1] : 1.0f - f[1]) * (dz ? f[2] : 1.0f - f[2]);
          const float* src = at(i[0] + dx, i[1] + dy, i[2] + dz);
          for (int ch = 0; ch < c; ++ch)
            dst[ch] += w * src[ch];
        }
      }
  return out;
}

std::vector<uint8_t> OccupiedCells(const RFGrid& grid)
{
  const int n = grid.cells, v = grid.Vertices(), c = grid.Channels();
  std::vector<uint8_t> occupied(size_t(n) * n * n, 0);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
      {
        bool any = false;
        for (int corner = 0; corner < 8 && !any; ++corner)
        {
          const size_t vertex = size_t(x + (corner & 1)) + size_t(v) * (size_t(y + ((corner >> 1) & 1)) + size_t(v) * size_t(z + (corner >> 2)));
          any = grid.values[vertex * c] > 0.0f;
        }
        occupied[size_t(x) + size_t(n) * (size_t(y) + size_t(n) * size_t(z))] = any ? 1 : 0;
      }
  return occupied;
}

size_t Prune(RFGrid& grid, float alphaThreshold)
{
  const int n = grid.cells, v = grid.Vertices(), c = grid.Channels();
  const float3 size = grid.boxMax - grid.boxMin;
  const float diagonal = LiteMath::length(size) / float(n);
  auto vertex = [&](int x, int y, int z) { return size_t(x) + size_t(v) * (size_t(y) + size_t(v) * size_t(z)); };
  // A cell is negligible when even its densest corner lets almost all light through.
  std::vector<uint8_t> keep(size_t(n) * n * n, 0);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
      {
        float densest = 0.0f;
        for (int corner = 0; corner < 8; ++corner)
          densest = std::max(densest, grid.values[vertex(x + (corner & 1), y + ((corner >> 1) & 1), z + (corner >> 2)) * c]);
        const float alpha = 1.0f - std::exp(-densest * grid.densityScale * diagonal);
        keep[size_t(x) + size_t(n) * (size_t(y) + size_t(n) * size_t(z))] = alpha >= alphaThreshold ? 1 : 0;
      }
  // A vertex keeps its density while any of its cells is kept.
  for (int z = 0; z < v; ++z)
    for (int y = 0; y < v; ++y)
      for (int x = 0; x < v; ++x)
      {
        bool kept = false;
        for (int cz = std::max(z - 1, 0); cz <= std::min(z, n - 1) && !kept; ++cz)
          for (int cy = std::max(y - 1, 0); cy <= std::min(y, n - 1) && !kept; ++cy)
            for (int cx = std::max(x - 1, 0); cx <= std::min(x, n - 1) && !kept; ++cx)
              kept = keep[size_t(cx) + size_t(n) * (size_t(cy) + size_t(n) * size_t(cz))] != 0;
        float& density = grid.values[vertex(x, y, z) * c];
        if (!kept)
          density = std::min(density, 0.0f);
      }
  const std::vector<uint8_t> occupied = OccupiedCells(grid);
  return size_t(std::count(occupied.begin(), occupied.end(), uint8_t(1)));
}

std::string Problem(const RFGrid& grid)
{
  if (grid.shDegree < 0 || grid.shDegree > 2)
    return "spherical harmonics degree must be 0, 1 or 2, not " + std::to_string(grid.shDegree);
  if (grid.cells < 1)
    return "a grid needs at least one cell per axis, not " + std::to_string(grid.cells);
  const size_t expected = size_t(grid.Vertices()) * grid.Vertices() * grid.Vertices() * grid.Channels();
  if (grid.values.size() != expected)
    return "a grid of " + std::to_string(grid.cells) + " cells and degree " + std::to_string(grid.shDegree) + " holds " + std::to_string(expected) +
           " values, not " + std::to_string(grid.values.size());
  if (!(grid.boxMin.x < grid.boxMax.x && grid.boxMin.y < grid.boxMax.y && grid.boxMin.z < grid.boxMax.z))
    return "the grid's box is empty";
  if (!(grid.densityScale > 0.0f) || !std::isfinite(grid.densityScale))
    return "the density scale must be positive";
  return "";
}

namespace {

constexpr char kMagic[5] = {'C', 'R', 'T', 'R', 'F'};

struct ModelHeader
{
  char magic[5];
  char pad[3];
  uint32_t version;
  int32_t cells, shDegree;
  float boxMin[3], boxMax[3];
  float densityScale;
  uint64_t count;
};

}  // namespace

void SaveModel(const std::string& path, const RFGrid& grid)
{
  if (std::string why = Problem(grid); !why.empty())
    throw std::runtime_error(path + ": cannot save this grid: " + why);
  ModelHeader h{};
  std::memcpy(h.magic, kMagic, sizeof(kMagic));
  h.version = kModelVersion;
  h.cells = grid.cells;
  h.shDegree = grid.shDegree;
  for (int a = 0; a < 3; ++a)
  {
    h.boxMin[a] = grid.boxMin[a];
    h.boxMax[a] = grid.boxMax[a];
  }
  h.densityScale = grid.densityScale;
  h.count = grid.values.size();
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(&h), sizeof(h));
  out.write(reinterpret_cast<const char*>(grid.values.data()), std::streamsize(grid.values.size() * sizeof(float)));
  if (!out)
    throw std::runtime_error(path + ": cannot write the model");
}

RFGrid LoadModel(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw std::runtime_error(path + ": cannot open the model");
  ModelHeader h{};
  if (!in.read(reinterpret_cast<char*>(&h), sizeof(h)) || std::memcmp(h.magic, kMagic, sizeof(kMagic)) != 0)
    throw std::runtime_error(path + ": not a radiance-field model (no CRTRF header)");
  if (h.version != kModelVersion)
    throw std::runtime_error(path + ": model version " + std::to_string(h.version) + ", but this program reads version " + std::to_string(kModelVersion) +
                             ": train it again with this version");
  RFGrid g;
  g.cells = h.cells;
  g.shDegree = h.shDegree;
  g.boxMin = float3(h.boxMin[0], h.boxMin[1], h.boxMin[2]);
  g.boxMax = float3(h.boxMax[0], h.boxMax[1], h.boxMax[2]);
  g.densityScale = h.densityScale;
  // The header first, so that a damaged count never sizes an allocation.
  if (h.shDegree < 0 || h.shDegree > 2 || h.cells < 1 || h.cells > 4096)
    throw std::runtime_error(path + ": the model's header is damaged (" + std::to_string(h.cells) + " cells, degree " + std::to_string(h.shDegree) + ")");
  const uint64_t expected = uint64_t(g.Vertices()) * g.Vertices() * g.Vertices() * g.Channels();
  if (h.count != expected)
    throw std::runtime_error(path + ": the model holds " + std::to_string(h.count) + " values where its grid needs " + std::to_string(expected));
  g.values.resize(size_t(h.count));
  if (!in.read(reinterpret_cast<char*>(g.values.data()), std::streamsize(g.values.size() * sizeof(float))))
    throw std::runtime_error(path + ": the model is cut short");
  if (std::string why = Problem(g); !why.empty())
    throw std::runtime_error(path + ": " + why);
  return g;
}

}  // namespace literf
