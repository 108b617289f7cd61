// Rays against whole SDFs, as references: sphere tracing for analytic SDFs and the dense grid, and
// every voxel (SVS) or brick (SBS) tested in turn. A BVH over the voxels or bricks replaces the
// loops in the ray tracing stack; these give its expected answers. A ray that starts inside the
// surface hits: at its start where the set stores its voxel, else where it enters the first stored
// voxel, before it could leave the shape.
#pragma once
#include "SdfStructures.h"

namespace litesdf {

// Sphere tracing: steps of the distance until it falls below `epsilon`; -1 when the ray leaves
// [tmin, tmax] or takes more than `maxSteps`.
inline float SphereTrace(const ISdf& sdf, float3 origin, float3 dir, float tmin, float tmax, float epsilon, int maxSteps) {
  float t = tmin;
  for (int i = 0; i < maxSteps && t <= tmax; ++i) {
    const float d = sdf.Distance(origin + t * dir);
    if (!(d > epsilon)) return d <= epsilon ? t : -1.0f;  // NaN misses
    t += d;
  }
  return -1.0f;
}

inline float SphereTraceGrid(const SdfGrid& grid, float3 origin, float3 dir, float tmin, float tmax, float epsilon, int maxSteps) {
  float tNear = 0.0f, tFar = 0.0f;
  const float3 invDir = float3(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z);
  const float3 boxMax = grid.boxMin + float3(grid.boxSize, grid.boxSize, grid.boxSize);
  if (!RayBox(origin, invDir, grid.boxMin, boxMax, tmin, tmax, tNear, tFar)) return -1.0f;
  float t = tNear;
  for (int i = 0; i < maxSteps && t <= tFar; ++i) {
    const float d = grid.Sample(origin + t * dir);
    if (!(d > epsilon)) return d <= epsilon ? t : -1.0f;
    t += d;
  }
  return -1.0f;
}

inline SdfHit TraceSVS(const SdfSVS& svs, float3 origin, float3 dir, float tmin, float tmax, int newtonIterations) {
  SdfHit best = Missed();
  const float size = svs.VoxelSize();
  for (size_t i = 0; i < svs.VoxelCount(); ++i) {
    const SdfHit h = IntersectVoxel(svs.Values(i), svs.VoxelMin(i), size, origin, dir, tmin, best.t >= 0.0f ? best.t : tmax, newtonIterations);
    if (h.t >= 0.0f && (best.t < 0.0f || h.t < best.t)) best = h;
  }
  return best;
}

inline SdfHit TraceSBS(const SdfSBS& sbs, float3 origin, float3 dir, float tmin, float tmax, int newtonIterations) {
  SdfHit best = Missed();
  const float size = sbs.VoxelSize(), brickExtent = size * float(sbs.brickSize);
  const float3 invDir = float3(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z);
  for (size_t b = 0; b < sbs.BrickCount(); ++b) {
    const float3 brickMin = sbs.BrickMin(b);
    float tNear = 0.0f, tFar = 0.0f;
    const float limit = best.t >= 0.0f ? best.t : tmax;
    if (!RayBox(origin, invDir, brickMin, brickMin + float3(brickExtent, brickExtent, brickExtent), tmin, limit, tNear, tFar)) continue;
    for (uint32_t z = 0; z < sbs.brickSize; ++z)
      for (uint32_t y = 0; y < sbs.brickSize; ++y)
        for (uint32_t x = 0; x < sbs.brickSize; ++x) {
          const float3 voxelMin = brickMin + size * float3(float(x), float(y), float(z));
          const float until = best.t >= 0.0f ? best.t : tmax;
          const SdfHit h = IntersectVoxel(sbs.Values(b, x, y, z), voxelMin, size, origin, dir, tmin, until, newtonIterations);
          if (h.t >= 0.0f && (best.t < 0.0f || h.t < best.t)) best = h;
        }
  }
  return best;
}

}  // namespace litesdf
