// Quantisation, packing and the builders of SdfStructures.h.
#include "SdfStructures.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <cmath>
#include <exception>
#include <functional>
#include <stdexcept>
#include <string>

namespace litesdf {

namespace {

uint32_t MaxCode(uint32_t bytesPerValue) { return bytesPerValue >= 4 ? 0xFFFFFFFFu : (1u << (8 * bytesPerValue)) - 1u; }

// What is wrong with a knob, or "" (the builders throw it, Problem() returns it).
std::string BytesProblem(uint32_t bytesPerValue) {
  return bytesPerValue == 1 || bytesPerValue == 2 || bytesPerValue == 4 ? ""
                                                                          : "bytes per value must be 1, 2 or 4, not " + std::to_string(bytesPerValue);
}
std::string DepthProblem(uint32_t depth) {
  return depth <= 10 ? "" : "depth must be at most 10 (1024 voxels per axis), not " + std::to_string(depth);
}
std::string BrickProblem(uint32_t brickSize, uint32_t depth) {
  const bool powerOf2 = brickSize != 0 && (brickSize & (brickSize - 1)) == 0;
  return powerOf2 && depth <= 10 && brickSize <= (1u << depth)
             ? ""
             : "brick size must be a power of 2 no larger than 2^depth, not " + std::to_string(brickSize);
}
void Check(const std::string& problem) {
  if (!problem.empty()) throw std::invalid_argument(problem);
}

uint32_t PackCoords(uint32_t x, uint32_t y, uint32_t z) { return x | (y << 10) | (z << 20); }
float3 UnpackCoords(uint32_t c) { return float3(float(c & 1023u), float((c >> 10) & 1023u), float((c >> 20) & 1023u)); }

// Runs body(i) for i in [0, count) on all cores. An exception thrown by one (an ISdf's) is
// rethrown here, after the loop: one may not leave an OpenMP region.
void ParallelFor(size_t count, const std::function<void(size_t)>& body) {
  std::exception_ptr failure;
#pragma omp parallel for schedule(dynamic, 64)
  for (size_t i = 0; i < count; ++i) {
    try {
      body(i);
    } catch (...) {
#pragma omp critical(litesdf_build_failure)
      if (!failure) failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
}

// The cells of level `level` (2^level per axis) that the surface may cross, packed, in Morton
// order: the octree is descended a level at a time, and a cell is dropped when the distance at its
// centre exceeds half its diagonal (then no point of it is on the surface, the distance being
// 1-Lipschitz, or a lower bound). Each level's cells are tested on all cores.
std::vector<uint32_t> CrossableCells(const ISdf& sdf, float3 boxMin, float boxSize, uint32_t level, SdfBuildStats& stats) {
  std::vector<uint32_t> cells = {PackCoords(0, 0, 0)};
  for (uint32_t l = 0;; ++l) {
    const float size = boxSize / float(1u << l);
    std::vector<char> crossable(cells.size());
    ParallelFor(cells.size(), [&](size_t i) {
      const float3 center = boxMin + size * (UnpackCoords(cells[i]) + float3(0.5f, 0.5f, 0.5f));
      crossable[i] = sdf.UnsignedDistance(center) <= 0.5f * std::sqrt(3.0f) * size;  // NaN: dropped too
    });
    stats.cellsVisited += cells.size();
    std::vector<uint32_t> kept;
    for (size_t i = 0; i < cells.size(); ++i)
      if (crossable[i]) kept.push_back(cells[i]);
    if (l == level) return kept;
    cells.clear();
    for (uint32_t cell : kept) {
      const uint32_t x = cell & 1023u, y = (cell >> 10) & 1023u, z = (cell >> 20) & 1023u;
      for (uint32_t c = 0; c < 8; ++c) cells.push_back(PackCoords(2 * x + (c & 1), 2 * y + ((c >> 1) & 1), 2 * z + (c >> 2)));
    }
  }
}

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

uint32_t QuantiseDistance(float d, float diagonal, uint32_t bytesPerValue) {
  if (bytesPerValue >= 4) {
    uint32_t bits;
    std::memcpy(&bits, &d, sizeof bits);
    return bits;
  }
  const float unit = LiteMath::clamp(d / diagonal, -1.0f, 1.0f) * 0.5f + 0.5f;
  return uint32_t(std::lround(double(unit) * MaxCode(bytesPerValue)));
}

float DequantiseDistance(uint32_t code, float diagonal, uint32_t bytesPerValue) {
  if (bytesPerValue >= 4) {
    float d;
    std::memcpy(&d, &code, sizeof d);
    return d;
  }
  return (float(code) / float(MaxCode(bytesPerValue)) * 2.0f - 1.0f) * diagonal;
}

void PackValue(std::vector<uint32_t>& words, size_t index, uint32_t code, uint32_t bytesPerValue) {
  if (bytesPerValue >= 4) {
    words[index] = code;
    return;
  }
  const uint32_t perWord = 4 / bytesPerValue, shift = uint32_t(index % perWord) * 8 * bytesPerValue;
  uint32_t& w = words[index / perWord];
  w = (w & ~(MaxCode(bytesPerValue) << shift)) | (code << shift);
}

uint32_t UnpackValue(const std::vector<uint32_t>& words, size_t index, uint32_t bytesPerValue) {
  if (bytesPerValue >= 4) return words[index];
  const uint32_t perWord = 4 / bytesPerValue, shift = uint32_t(index % perWord) * 8 * bytesPerValue;
  return (words[index / perWord] >> shift) & MaxCode(bytesPerValue);
}

float SdfGrid::Sample(float3 p) const {
  const float cell = CellSize();
  const float3 u = LiteMath::clamp((p - boxMin) / cell, 0.0f, float(samples - 1) - 1e-4f);
  const uint32_t x = uint32_t(u.x), y = uint32_t(u.y), z = uint32_t(u.z);
  VoxelValues v;
  for (uint32_t c = 0; c < 8; ++c) v.v[c] = Value(x + (c & 1), y + ((c >> 1) & 1), z + (c >> 2));
  return EvalTrilinear(TrilinearOf(v), u - float3(float(x), float(y), float(z)));
}

float3 SdfSVS::VoxelMin(size_t i) const { return boxMin + VoxelSize() * UnpackCoords(coords[i]); }

VoxelValues SdfSVS::Values(size_t i) const {
  const float diagonal = std::sqrt(3.0f) * VoxelSize();
  VoxelValues v;
  for (uint32_t c = 0; c < 8; ++c) v.v[c] = DequantiseDistance(UnpackValue(values, 8 * i + c, bytesPerValue), diagonal, bytesPerValue);
  return v;
}

float3 SdfSBS::BrickMin(size_t brick) const { return boxMin + VoxelSize() * UnpackCoords(coords[brick]); }

VoxelValues SdfSBS::Values(size_t brick, uint32_t x, uint32_t y, uint32_t z) const {
  const float diagonal = std::sqrt(3.0f) * VoxelSize();
  const uint32_t n = brickSize + 1;
  const size_t first = size_t(brick) * WordsPerBrick() * (4 / std::min(bytesPerValue, 4u));
  VoxelValues v;
  for (uint32_t c = 0; c < 8; ++c) {
    const uint32_t cx = x + (c & 1), cy = y + ((c >> 1) & 1), cz = z + (c >> 2);
    v.v[c] = DequantiseDistance(UnpackValue(values, first + (cz * n + cy) * n + cx, bytesPerValue), diagonal, bytesPerValue);
  }
  return v;
}

namespace {
std::string CubeProblem(float3 boxMin, float boxSize, uint32_t depth, uint32_t bytesPerValue) {
  if (!(boxSize > 0.0f) || !std::isfinite(boxSize) || !std::isfinite(boxMin.x + boxMin.y + boxMin.z))
    return "the field's cube is empty or not finite";
  if (std::string p = DepthProblem(depth); !p.empty()) return p;
  return BytesProblem(bytesPerValue);
}

// A voxel's or brick's packed first voxel (x | y << 10 | z << 20) whose `extent` voxels per axis do
// not fit in the 2^depth of the cube, or "".
std::string CoordProblem(uint32_t packed, uint32_t extent, uint32_t depth) {
  const uint32_t x = packed & 1023u, y = (packed >> 10) & 1023u, z = (packed >> 20) & 1023u, side = 1u << depth;
  if ((packed >> 30) != 0 || x + extent > side || y + extent > side || z + extent > side)
    return "at (" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) + ") is outside the cube's " + std::to_string(side) +
           "^3 voxels";
  return "";
}
}  // namespace

std::string Problem(const SdfGrid& grid) {
  if (grid.samples < 2 || grid.values.size() != size_t(grid.samples) * grid.samples * grid.samples)
    return std::to_string(grid.values.size()) + " values for " + std::to_string(grid.samples) + "^3 samples (at least 2 per axis)";
  return CubeProblem(grid.boxMin, grid.boxSize, 0, 4);
}

std::string Problem(const SdfSVS& svs) {
  if (std::string p = CubeProblem(svs.boxMin, svs.boxSize, svs.depth, svs.bytesPerValue); !p.empty()) return p;
  if (svs.values.size() != svs.coords.size() * 8 * svs.bytesPerValue / 4)
    return std::to_string(svs.values.size()) + " words of values for " + std::to_string(svs.coords.size()) + " voxels";
  for (size_t i = 0; i < svs.coords.size(); ++i)
    if (std::string p = CoordProblem(svs.coords[i], 1, svs.depth); !p.empty()) return "voxel " + std::to_string(i) + " " + p;
  return "";
}

std::string Problem(const SdfSBS& sbs) {
  if (std::string p = CubeProblem(sbs.boxMin, sbs.boxSize, sbs.depth, sbs.bytesPerValue); !p.empty()) return p;
  if (std::string p = BrickProblem(sbs.brickSize, sbs.depth); !p.empty()) return p;
  if (sbs.values.size() != sbs.coords.size() * sbs.WordsPerBrick())
    return std::to_string(sbs.values.size()) + " words of values for " + std::to_string(sbs.coords.size()) + " bricks of " +
           std::to_string(sbs.brickSize) + "^3 voxels";
  for (size_t i = 0; i < sbs.coords.size(); ++i)
    if (std::string p = CoordProblem(sbs.coords[i], sbs.brickSize, sbs.depth); !p.empty()) return "brick " + std::to_string(i) + " " + p;
  return "";
}

SdfGrid BuildGrid(const ISdf& sdf, float3 boxMin, float boxSize, uint32_t samples) {
  if (samples < 2) throw std::invalid_argument("a grid needs at least 2 samples per axis");
  SdfGrid grid;
  grid.samples = samples;
  grid.boxMin = boxMin;
  grid.boxSize = boxSize;
  grid.values.resize(size_t(samples) * samples * samples);
  const float cell = grid.CellSize();
  ParallelFor(size_t(samples) * samples, [&](size_t zy) {
    const uint32_t z = uint32_t(zy / samples), y = uint32_t(zy % samples);
    for (uint32_t x = 0; x < samples; ++x)
      grid.values[zy * samples + x] = sdf.Distance(boxMin + cell * float3(float(x), float(y), float(z)));
  });
  return grid;
}

SdfSVS BuildSVS(const ISdf& sdf, float3 boxMin, float boxSize, uint32_t depth, uint32_t bytesPerValue, SdfBuildStats* stats) {
  Check(BytesProblem(bytesPerValue));
  Check(DepthProblem(depth));
  const auto t0 = std::chrono::steady_clock::now();
  SdfBuildStats local;
  SdfBuildStats& s = stats ? *stats : local;
  SdfSVS svs;
  svs.boxMin = boxMin;
  svs.boxSize = boxSize;
  svs.depth = depth;
  svs.bytesPerValue = bytesPerValue;
  const float size = svs.VoxelSize(), diagonal = std::sqrt(3.0f) * size;
  const std::vector<uint32_t> cells = CrossableCells(sdf, boxMin, boxSize, depth, s);
  std::vector<float> corners(8 * cells.size());
  ParallelFor(cells.size(), [&](size_t i) {
    const float3 at = UnpackCoords(cells[i]);
    for (uint32_t c = 0; c < 8; ++c)
      corners[8 * i + c] = sdf.Distance(boxMin + size * (at + float3(float(c & 1), float((c >> 1) & 1), float(c >> 2))));
  });
  s.voxelsCrossable += cells.size();
  for (size_t i = 0; i < cells.size(); ++i) {
    const float* corner = &corners[8 * i];
    const float lo = *std::min_element(corner, corner + 8), hi = *std::max_element(corner, corner + 8);
    if (!(lo <= 0.0f && hi >= 0.0f)) continue;  // the interpolant keeps its sign: no surface here
    ++s.voxelsKept;
    svs.coords.push_back(cells[i]);
    const size_t first = svs.values.size() * (4 / bytesPerValue);
    svs.values.resize(svs.values.size() + 8 * bytesPerValue / 4, 0u);
    for (uint32_t c = 0; c < 8; ++c) PackValue(svs.values, first + c, QuantiseDistance(corner[c], diagonal, bytesPerValue), bytesPerValue);
  }
  s.milliseconds = MsSince(t0);
  return svs;
}

SdfSVS BuildSVSWithinBudget(const ISdf& sdf, float3 boxMin, float boxSize, uint32_t maxDepth, uint32_t bytesPerValue, size_t maxBytes,
                            SdfBuildStats* stats) {
  Check(DepthProblem(maxDepth));
  SdfSVS best;
  bool found = false;
  for (uint32_t depth = 1; depth <= maxDepth; ++depth) {
    SdfBuildStats s;
    SdfSVS svs = BuildSVS(sdf, boxMin, boxSize, depth, bytesPerValue, &s);
    if (svs.Bytes() > maxBytes) break;
    best = std::move(svs);
    found = true;
    if (stats) *stats = s;
  }
  if (!found)
    throw std::invalid_argument("no sparse voxel set of this SDF fits in " + std::to_string(maxBytes) + " bytes, not even at depth 1");
  return best;
}

SdfSBS BuildSBS(const ISdf& sdf, float3 boxMin, float boxSize, uint32_t depth, uint32_t brickSize, uint32_t bytesPerValue,
                SdfBuildStats* stats) {
  Check(BytesProblem(bytesPerValue));
  Check(DepthProblem(depth));
  Check(BrickProblem(brickSize, depth));
  uint32_t brickLevels = 0;
  while ((1u << brickLevels) < brickSize) ++brickLevels;
  const auto t0 = std::chrono::steady_clock::now();
  SdfBuildStats local;
  SdfBuildStats& s = stats ? *stats : local;
  SdfSBS sbs;
  sbs.boxMin = boxMin;
  sbs.boxSize = boxSize;
  sbs.depth = depth;
  sbs.brickSize = brickSize;
  sbs.bytesPerValue = bytesPerValue;
  const float size = sbs.VoxelSize(), diagonal = std::sqrt(3.0f) * size;
  const uint32_t n = brickSize + 1;
  const size_t valuesPerBrick = size_t(n) * n * n;
  const std::vector<uint32_t> cells = CrossableCells(sdf, boxMin, boxSize, depth - brickLevels, s);
  std::vector<float> values(valuesPerBrick * cells.size());
  ParallelFor(cells.size(), [&](size_t i) {
    const float3 at = float(brickSize) * UnpackCoords(cells[i]);
    float* brick = &values[valuesPerBrick * i];
    for (uint32_t z = 0; z < n; ++z)
      for (uint32_t y = 0; y < n; ++y)
        for (uint32_t x = 0; x < n; ++x) brick[(z * n + y) * n + x] = sdf.Distance(boxMin + size * (at + float3(float(x), float(y), float(z))));
  });
  for (size_t i = 0; i < cells.size(); ++i) {
    const float* brick = &values[valuesPerBrick * i];
    bool keep = false;
    for (uint32_t z = 0; z < brickSize; ++z)
      for (uint32_t y = 0; y < brickSize; ++y)
        for (uint32_t x = 0; x < brickSize; ++x) {
          ++s.voxelsCrossable;
          float lo = brick[(z * n + y) * n + x], hi = lo;
          for (uint32_t c = 1; c < 8; ++c) {
            const float v = brick[((z + (c >> 2)) * n + y + ((c >> 1) & 1)) * n + x + (c & 1)];
            lo = std::min(lo, v);
            hi = std::max(hi, v);
          }
          if (lo <= 0.0f && hi >= 0.0f) {
            ++s.voxelsKept;
            keep = true;
          }
        }
    if (!keep) continue;
    const float3 at = float(brickSize) * UnpackCoords(cells[i]);
    sbs.coords.push_back(PackCoords(uint32_t(at.x), uint32_t(at.y), uint32_t(at.z)));
    const size_t firstWord = sbs.values.size();
    sbs.values.resize(firstWord + sbs.WordsPerBrick(), 0u);
    const size_t first = firstWord * (4 / bytesPerValue);
    for (uint32_t v = 0; v < valuesPerBrick; ++v)
      PackValue(sbs.values, first + v, QuantiseDistance(brick[v], diagonal, bytesPerValue), bytesPerValue);
  }
  s.milliseconds = MsSince(t0);
  return sbs;
}

}  // namespace litesdf

