// CreateSceneRT: every ray tracing implementation known to this build, by name.
#include "BVHScene.h"
#include "CrossRT.h"
#include "LBVH.h"
#include "SAHBuilder.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <string>

std::shared_ptr<ISceneObject> CreateEmbreeRT();  // EmbreeRT.cpp

namespace {

// The LBVH as written (single-threaded); BVHScene with LBVH_CPU or LBVH_Vulkan builds in parallel.
BVHScene::Builder LbvhBuilder()
{
  auto builder = std::make_shared<LBVH>();
  return [builder](const LiteMath::Box4f* boxes, int count) { return BuildLBVH(*builder, boxes, count); };
}

}  // namespace

std::shared_ptr<ISceneObject> CreateSceneRT(const char* name)
{
  std::string key = name ? name : "";
  std::transform(key.begin(), key.end(), key.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (key == "embree")
    return CreateEmbreeRT();
  if (key == "lbvh")
    return std::make_shared<BVHScene>("lbvh", LbvhBuilder());
  if (key == "sah")
    return std::make_shared<BVHScene>("sah", [](const LiteMath::Box4f* boxes, int count) { return BuildBinnedSAH(boxes, count); });
  throw std::invalid_argument("CreateSceneRT: unknown implementation '" + std::string(name ? name : "(null)") +
                              "'; known implementations: embree, lbvh, sah");
}
