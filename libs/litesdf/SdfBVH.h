// A BVH over the voxels of a sparse voxel set or the bricks of a sparse brick set, built by
// litebvh's binned SAH builder, and the traversal that calls the voxel intersection (SdfVoxel.h)
// per leaf box: the nearest hit, children visited nearer first, pruned by the hit so far.
#pragma once
#include "BVHNode.h"
#include "SdfLeaves.h"

#include <cmath>

namespace litesdf {

BVHTree BuildSdfBVH(const SdfSVS& svs);
BVHTree BuildSdfBVH(const SdfSBS& sbs);

namespace detail {
// Visits the leaves whose boxes the ray enters before `limit()`, nearer child first; `leaf(first,
// count)` tests a leaf's primitives.
template <class Limit, class Leaf>
void TraverseBVH(const BVHTree& bvh, float3 origin, float3 dir, float tmin, Limit limit, Leaf leaf) {
  if (bvh.nodes.empty()) return;
  const float3 invDir = float3(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z);
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BVHNode& node = bvh.nodes[stack[--top]];
    float t0 = 0.0f, t1 = 0.0f;
    if (!RayBox(origin, invDir, node.boxMin, node.boxMax, tmin, limit(), t0, t1)) continue;
    if (node.left & kLeafFlag) {
      leaf(node.left & ~kLeafFlag, node.right);
      continue;
    }
    float l0 = 0.0f, l1 = 0.0f, r0 = 0.0f, r1 = 0.0f;
    const BVHNode& l = bvh.nodes[node.left];
    const BVHNode& r = bvh.nodes[node.right];
    const bool hitL = RayBox(origin, invDir, l.boxMin, l.boxMax, tmin, limit(), l0, l1);
    const bool hitR = RayBox(origin, invDir, r.boxMin, r.boxMax, tmin, limit(), r0, r1);
    if (top + 2 > 64) return;  // deeper than any tree the builders make
    if (hitL && hitR) {
      stack[top++] = l0 <= r0 ? node.right : node.left;  // the farther one waits
      stack[top++] = l0 <= r0 ? node.left : node.right;
    } else if (hitL) {
      stack[top++] = node.left;
    } else if (hitR) {
      stack[top++] = node.right;
    }
  }
}
}  // namespace detail

inline SdfHit TraceSVS(const SdfSVS& svs, const BVHTree& bvh, float3 origin, float3 dir, float tmin, float tmax, int newtonIterations) {
  SdfHit best = Missed();
  auto limit = [&]() { return best.t >= 0.0f ? best.t : tmax; };
  detail::TraverseBVH(bvh, origin, dir, tmin, limit, [&](uint32_t first, uint32_t count) {
    for (uint32_t i = first; i < first + count; ++i) {
      const SdfHit h = IntersectSVSVoxel(svs, bvh.primIndices[i], origin, dir, tmin, limit(), newtonIterations);
      if (h.t >= 0.0f && (best.t < 0.0f || h.t < best.t)) best = h;
    }
  });
  return best;
}

inline SdfHit TraceSBS(const SdfSBS& sbs, const BVHTree& bvh, float3 origin, float3 dir, float tmin, float tmax, int newtonIterations) {
  SdfHit best = Missed();
  auto limit = [&]() { return best.t >= 0.0f ? best.t : tmax; };
  detail::TraverseBVH(bvh, origin, dir, tmin, limit, [&](uint32_t first, uint32_t count) {
    for (uint32_t i = first; i < first + count; ++i) {
      const SdfHit h = IntersectSBSBrick(sbs, bvh.primIndices[i], origin, dir, tmin, limit(), newtonIterations);
      if (h.t >= 0.0f && (best.t < 0.0f || h.t < best.t)) best = h;
    }
  });
  return best;
}

}  // namespace litesdf
