// The BVHs of SdfBVH.h: litebvh's binned SAH builder over the cubes of voxels or bricks.
#include "SdfBVH.h"

#include "SAHBuilder.h"

#include <functional>

namespace litesdf {

namespace {
BVHTree BuildOverCubes(size_t count, float edge, const std::function<float3(size_t)>& cubeMin) {
  std::vector<LiteMath::Box4f> boxes(count);
  for (size_t i = 0; i < count; ++i) {
    const float3 lo = cubeMin(i), hi = lo + float3(edge, edge, edge);
    boxes[i] = LiteMath::Box4f(LiteMath::float4(lo.x, lo.y, lo.z, 0.0f), LiteMath::float4(hi.x, hi.y, hi.z, 0.0f));
  }
  return BuildBinnedSAH(boxes.data(), int(count), 4);
}
}  // namespace

BVHTree BuildSdfBVH(const SdfSVS& svs) {
  return BuildOverCubes(svs.VoxelCount(), svs.VoxelSize(), [&](size_t i) { return svs.VoxelMin(i); });
}

BVHTree BuildSdfBVH(const SdfSBS& sbs) {
  return BuildOverCubes(sbs.BrickCount(), sbs.VoxelSize() * float(sbs.brickSize), [&](size_t i) { return sbs.BrickMin(i); });
}

}  // namespace litesdf
