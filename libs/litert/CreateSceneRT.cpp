// CreateSceneRT: every ray tracing implementation known to this build, by name.
#include "BVHScene.h"
#include "CrossRT.h"
#include "LBVH.h"
#include "SAHBuilder.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <string>

std::unique_ptr<ISceneObject> CreateEmbreeRT();  // EmbreeRT.cpp

namespace {

// The LBVH as written (single-threaded); BVHScene with LBVH_CPU or LBVH_Vulkan builds in parallel.
BVHScene::Builder LbvhBuilder()
{
  auto builder = std::make_shared<LBVH>();
  return [builder](const LiteMath::Box4f* boxes, int count) { return BuildLBVH(*builder, boxes, count); };
}

}  // namespace

namespace {
std::string Lower(const char* name)
{
  std::string key = name ? name : "";
  std::transform(key.begin(), key.end(), key.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return key;
}

std::unique_ptr<ISceneObject> Create(const std::string& impl, const std::string& build, const char* name)
{
  if (impl == "embree")
    return CreateEmbreeRT();
  if (impl == "lbvh" || (impl.rfind("bvh", 0) == 0 && build == "lbvh"))
    return std::make_unique<BVHScene>("lbvh", LbvhBuilder());
  if (impl == "sah" || impl == "bvh2common" || impl == "bvh4common")
    return std::make_unique<BVHScene>("sah", [](const LiteMath::Box4f* boxes, int count) { return BuildBinnedSAH(boxes, count); });
  throw std::invalid_argument("CreateSceneRT: unknown implementation '" + std::string(name ? name : "(null)") +
                              "'; known implementations: embree, lbvh, sah (also BVH2Common, BVH4Common)");
}
}  // namespace

ISceneObject* CreateSceneRT(const char* implName) { return Create(Lower(implName), "", implName).release(); }

void DeleteSceneRT(ISceneObject* scene) { delete scene; }

std::shared_ptr<ISceneObject> CreateSceneRT(const char* implName, const char* buildName, const char* layoutName)
{
  (void)layoutName;
  return Create(Lower(implName), Lower(buildName), implName);
}
