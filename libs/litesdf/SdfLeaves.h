// One leaf of each structure against a ray, the unit a BVH (SdfBVH.h) or a ray tracing API's custom
// primitive (litert's Embree geometry) tests: a voxel of a sparse voxel set, a brick of a sparse
// brick set (its voxels walked along the ray), the whole dense grid (its cells walked the same way,
// those that cannot hold the surface skipped on their corner values).
#pragma once
#include "SdfStructures.h"

namespace litesdf {

inline SdfHit IntersectSVSVoxel(const SdfSVS& svs, size_t voxel, float3 origin, float3 dir, float tmin, float tmax, int newtonIterations) {
  return IntersectVoxel(svs.Values(voxel), svs.VoxelMin(voxel), svs.VoxelSize(), origin, dir, tmin, tmax, newtonIterations);
}

// The nearest hit in brick `brick` within [tmin, tmax]: its voxels in order along the ray, the first hit.
inline SdfHit IntersectSBSBrick(const SdfSBS& sbs, size_t brick, float3 origin, float3 dir, float tmin, float tmax, int newtonIterations) {
  const float size = sbs.VoxelSize(), extent = size * float(sbs.brickSize);
  const float3 brickMin = sbs.BrickMin(brick);
  const float3 invDir = float3(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z);
  float t0 = 0.0f, t1 = 0.0f;
  if (!RayBox(origin, invDir, brickMin, brickMin + float3(extent, extent, extent), tmin, tmax, t0, t1)) return Missed();
  const int n[3] = {int(sbs.brickSize), int(sbs.brickSize), int(sbs.brickSize)};
  return MarchVoxels(n, brickMin, size, origin, dir, t0, t1, [&](int x, int y, int z, float3 voxelMin, float tEnter, float tLeave) {
    const VoxelValues values = sbs.Values(brick, uint32_t(x), uint32_t(y), uint32_t(z));
    return MayHoldSurface(values) ? IntersectVoxelSpan(values, voxelMin, size, origin, dir, tEnter, tLeave, newtonIterations) : Missed();
  });
}

// The nearest hit on the dense grid's trilinear surface within [tmin, tmax].
inline SdfHit IntersectGrid(const SdfGrid& grid, float3 origin, float3 dir, float tmin, float tmax, int newtonIterations) {
  const float size = grid.CellSize();
  const float3 invDir = float3(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z);
  float t0 = 0.0f, t1 = 0.0f;
  const float3 boxMax = grid.boxMin + float3(grid.boxSize, grid.boxSize, grid.boxSize);
  if (grid.samples < 2 || !RayBox(origin, invDir, grid.boxMin, boxMax, tmin, tmax, t0, t1)) return Missed();
  const int cells = int(grid.samples) - 1;
  const int n[3] = {cells, cells, cells};
  return MarchVoxels(n, grid.boxMin, size, origin, dir, t0, t1, [&](int x, int y, int z, float3 voxelMin, float tEnter, float tLeave) {
    VoxelValues values;
    for (uint32_t c = 0; c < 8; ++c) values.v[c] = grid.Value(uint32_t(x) + (c & 1), uint32_t(y) + ((c >> 1) & 1), uint32_t(z) + (c >> 2));
    return MayHoldSurface(values) ? IntersectVoxelSpan(values, voxelMin, size, origin, dir, tEnter, tLeave, newtonIterations) : Missed();
  });
}

}  // namespace litesdf
