// RayTracingScene: bottom- and top-level acceleration structures for shaders that trace with
// GL_EXT_ray_query (meshes) or in ray tracing pipelines (leaf boxes). Lavapipe has neither, so this
// runs only on GPUs that have them.
#include "crossrt/VulkanRuntime.h"

#include "Internal.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

namespace crossrt {
namespace {

// Builds write acceleration structures; later builds and shaders read them.
void BuildBarrier(VkCommandBuffer cmd, VkPipelineStageFlags dstStages, VkAccessFlags dstAccess) {
  auto barrier = VkInit<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  barrier.dstAccessMask = dstAccess;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, dstStages, 0, 1, &barrier, 0, nullptr, 0,
                       nullptr);
}

// A bottom level's geometry of boxes (VkAabbPositionsKHR) at `boxes`, opaque: no any-hit shaders, so
// the intersection shader's report commits.
VkAccelerationStructureGeometryKHR AabbGeometry(VkDeviceAddress boxes) {
  auto geometry = VkInit<VkAccelerationStructureGeometryKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR);
  geometry.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
  geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  geometry.geometry.aabbs = VkInit<VkAccelerationStructureGeometryAabbsDataKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR);
  geometry.geometry.aabbs.data.deviceAddress = boxes;
  geometry.geometry.aabbs.stride = sizeof(VkAabbPositionsKHR);
  return geometry;
}
}  // namespace

RayTracingScene::RayTracingScene(std::shared_ptr<VulkanContext> ctx) : ctx_(std::move(ctx)) {
  if (!ctx_) throw Error("crossrt::RayTracingScene: null VulkanContext");
  if (!ctx_->hasRayQuery && !ctx_->hasRayTracingPipeline)
    throw Error("crossrt::RayTracingScene: device '" + std::string(ctx_->properties.deviceName) +
                "' has no acceleration structures (neither VK_KHR_ray_query nor VK_KHR_ray_tracing_pipeline)");
}

RayTracingScene::RayTracingScene(RayTracingScene&& other) noexcept { *this = std::move(other); }

RayTracingScene& RayTracingScene::operator=(RayTracingScene&& other) noexcept {
  if (this != &other) {
    Release();
    ctx_ = std::move(other.ctx_);
    bottomLevels_ = std::move(other.bottomLevels_);
    top_ = std::move(other.top_);
    topLevel_ = std::exchange(other.topLevel_, VK_NULL_HANDLE);
    other.top_.handle = VK_NULL_HANDLE;
  }
  return *this;
}

RayTracingScene::~RayTracingScene() { Release(); }

void RayTracingScene::Release() noexcept {
  if (!ctx_) return;
  if (top_.handle) ctx_->vkDestroyAccelerationStructureKHR(ctx_->device, top_.handle, nullptr);
  for (auto& level : bottomLevels_)
    if (level.handle) ctx_->vkDestroyAccelerationStructureKHR(ctx_->device, level.handle, nullptr);
  top_ = Level{};
  bottomLevels_.clear();
  topLevel_ = VK_NULL_HANDLE;
}

RayTracingScene::Level RayTracingScene::Create(VkAccelerationStructureTypeKHR type, VkDeviceSize bytes) {
  Level level;
  level.storage = Buffer(ctx_, bytes, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  auto info = VkInit<VkAccelerationStructureCreateInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR);
  info.buffer = level.storage.Handle();
  info.size = bytes;
  info.type = type;
  Check(ctx_->vkCreateAccelerationStructureKHR(ctx_->device, &info, nullptr, &level.handle), "vkCreateAccelerationStructureKHR");
  return level;
}

// A bottom level created and sized, with the input it is built from.
struct RayTracingScene::PendingLevel {
  Buffer input;  // vertices or boxes
  VkAccelerationStructureGeometryKHR geometry{};
  VkAccelerationStructureBuildGeometryInfoKHR build{};
  VkAccelerationStructureBuildRangeInfoKHR range{};
  VkDeviceSize scratchOffset = 0;
};

RayTracingScene::PendingLevel RayTracingScene::Prepare(const VkAccelerationStructureGeometryKHR& geometry, uint32_t primitiveCount,
                                                       VkDeviceSize& scratchBytes) {
  const VulkanContext& vk = *ctx_;
  PendingLevel p;
  p.geometry = geometry;
  p.build = VkInit<VkAccelerationStructureBuildGeometryInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR);
  p.build.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  p.build.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  p.build.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  p.build.geometryCount = 1;
  p.build.pGeometries = &p.geometry;
  p.range.primitiveCount = primitiveCount;
  auto sizes = VkInit<VkAccelerationStructureBuildSizesInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR);
  vk.vkGetAccelerationStructureBuildSizesKHR(vk.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &p.build, &p.range.primitiveCount, &sizes);
  Level level = Create(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, sizes.accelerationStructureSize);
  p.build.dstAccelerationStructure = level.handle;
  p.scratchOffset = scratchBytes;
  scratchBytes = AlignUp(scratchBytes + sizes.buildScratchSize, vk.accelerationScratchAlignment);
  bottomLevels_.push_back(std::move(level));
  return p;
}

void RayTracingScene::Build(const std::vector<Mesh>& meshes, const std::vector<Instance>& instances) {
  if (!ctx_) throw Error("crossrt::RayTracingScene::Build on a scene without a context");
  Release();
  const VulkanContext& vk = *ctx_;
  const VkBufferUsageFlags input = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;

  // Bottom levels: each non-empty mesh's triangles as a vertex soup (no index buffer).
  std::vector<PendingLevel> pending;
  pending.reserve(meshes.size());
  std::vector<int> levelOfMesh(meshes.size(), -1);
  VkDeviceSize scratchBytes = 0;
  for (size_t m = 0; m < meshes.size(); ++m) {
    const Mesh& mesh = meshes[m];
    if (mesh.triangleCount == 0) continue;
    if (mesh.triangleCount > 0x7FFFFFFFu / 3) throw Error("crossrt::RayTracingScene: mesh " + std::to_string(m) + " has too many triangles");
    const size_t bytes = sizeof(float) * 9 * mesh.triangleCount;
    Buffer vertices(ctx_, bytes, input);
    // Zero-area triangles are never hit (CrossRT.h), but Vulkan leaves their intersection to the
    // implementation (lavapipe reports hits on them): a NaN x makes them inactive, which the spec
    // defines as never hit. Primitive indices stay as they are.
    std::vector<float> soup(mesh.triangles, mesh.triangles + 9 * mesh.triangleCount);
    for (size_t t = 0; t < mesh.triangleCount; ++t) {
      const float* v = &soup[9 * t];
      const double e1[3] = {double(v[3]) - v[0], double(v[4]) - v[1], double(v[5]) - v[2]};
      const double e2[3] = {double(v[6]) - v[0], double(v[7]) - v[1], double(v[8]) - v[2]};
      const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) soup[9 * t] = std::numeric_limits<float>::quiet_NaN();
    }
    vertices.Upload(soup.data(), bytes);
    auto geometry = VkInit<VkAccelerationStructureGeometryKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR);
    geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    auto& tri = geometry.geometry.triangles;
    tri = VkInit<VkAccelerationStructureGeometryTrianglesDataKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR);
    tri.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    tri.vertexData.deviceAddress = vertices.Address();
    tri.vertexStride = 3 * sizeof(float);
    tri.maxVertex = static_cast<uint32_t>(3 * mesh.triangleCount - 1);
    tri.indexType = VK_INDEX_TYPE_NONE_KHR;
    levelOfMesh[m] = static_cast<int>(bottomLevels_.size());
    pending.push_back(Prepare(geometry, static_cast<uint32_t>(mesh.triangleCount), scratchBytes));
    pending.back().input = std::move(vertices);
  }

  // The top level: one instance per entry, in order; an instance of an empty mesh references no
  // bottom level (Vulkan treats it as inactive) and has mask 0 (no ray's cull mask matches it).
  std::vector<VkAccelerationStructureInstanceKHR> records(instances.size());
  for (size_t i = 0; i < instances.size(); ++i) {
    const Instance& in = instances[i];
    if (in.mesh >= meshes.size())
      throw Error("crossrt::RayTracingScene: instance " + std::to_string(i) + " places mesh " + std::to_string(in.mesh) + " of " +
                  std::to_string(meshes.size()));
    if (in.mesh >= (1u << 24)) throw Error("crossrt::RayTracingScene: mesh ids must fit the 24-bit custom index");
    VkAccelerationStructureInstanceKHR& r = records[i];
    std::memcpy(r.transform.matrix, in.toWorldRows, sizeof(r.transform.matrix));
    r.instanceCustomIndex = in.mesh;
    r.mask = levelOfMesh[in.mesh] >= 0 ? 0xFF : 0x00;
    r.instanceShaderBindingTableRecordOffset = 0;
    r.flags = VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR;
    if (levelOfMesh[in.mesh] >= 0) {
      auto addressInfo = VkInit<VkAccelerationStructureDeviceAddressInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR);
      addressInfo.accelerationStructure = bottomLevels_[size_t(levelOfMesh[in.mesh])].handle;
      r.accelerationStructureReference = vk.vkGetAccelerationStructureDeviceAddressKHR(vk.device, &addressInfo);
    }
  }
  BuildLevels(pending, scratchBytes, records);
}

void RayTracingScene::CheckLeafBoxes(const std::vector<LeafBox>& leaves, const std::string& what) {
  for (size_t i = 0; i < leaves.size(); ++i) {
    if (leaves[i].hitGroup >= (1u << 24))
      throw Error("crossrt::RayTracingScene: the hit group of " + what + "[" + std::to_string(i) + "] does not fit the 24-bit record offset");
    for (int a = 0; a < 3; ++a)
      if (!(leaves[i].min[a] <= leaves[i].max[a]) || !std::isfinite(leaves[i].max[a] - leaves[i].min[a]))
        throw Error("crossrt::RayTracingScene: the box of " + what + "[" + std::to_string(i) + "] is not a finite box with min <= max (axis " +
                    std::to_string(a) + ": " + std::to_string(leaves[i].min[a]) + " to " + std::to_string(leaves[i].max[a]) + ")");
  }
  if (leaves.size() >= (1u << 24)) throw Error("crossrt::RayTracingScene: " + what + " has more leaves than 24-bit instance ids name");
}

void RayTracingScene::BuildLeaves(const std::vector<LeafBox>& leaves, const std::string& what) {
  if (!ctx_) throw Error("crossrt::RayTracingScene::BuildLeaves on a scene without a context");
  CheckLeafBoxes(leaves, what);
  Release();
  const VulkanContext& vk = *ctx_;
  // One bottom level, the unit box; each leaf is an instance scaling it onto the leaf's box.
  const VkAabbPositionsKHR unit{0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 1.0f};
  Buffer box(ctx_, sizeof(unit), VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  box.Upload(&unit, sizeof(unit));
  const VkAccelerationStructureGeometryKHR geometry = AabbGeometry(box.Address());
  VkDeviceSize scratchBytes = 0;
  std::vector<PendingLevel> pending;
  pending.push_back(Prepare(geometry, 1, scratchBytes));
  pending.back().input = std::move(box);
  auto addressInfo = VkInit<VkAccelerationStructureDeviceAddressInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR);
  addressInfo.accelerationStructure = bottomLevels_[0].handle;
  const VkDeviceAddress unitBox = vk.vkGetAccelerationStructureDeviceAddressKHR(vk.device, &addressInfo);

  std::vector<VkAccelerationStructureInstanceKHR> records(leaves.size());
  for (size_t i = 0; i < leaves.size(); ++i) {
    const LeafBox& leaf = leaves[i];
    VkAccelerationStructureInstanceKHR& r = records[i];
    // A singular transform would leave the hardware no ray in the box's space: a flat box gets
    // a sliver of thickness, relative to its distance from the origin. Rays meet it a little early
    // or late; the intersection shader's own test decides the hit.
    float largest = 1.0f;
    for (int a = 0; a < 3; ++a) largest = std::max({largest, std::fabs(leaf.min[a]), std::fabs(leaf.max[a])});
    for (int a = 0; a < 3; ++a) {
      const float extent = std::max(leaf.max[a] - leaf.min[a], largest * 1e-6f);
      r.transform.matrix[a][a] = extent;
      r.transform.matrix[a][3] = leaf.min[a];
    }
    r.instanceCustomIndex = static_cast<uint32_t>(i);
    r.mask = 0xFF;
    r.instanceShaderBindingTableRecordOffset = leaf.hitGroup;
    r.flags = VK_GEOMETRY_INSTANCE_FORCE_OPAQUE_BIT_KHR;
    r.accelerationStructureReference = unitBox;
  }
  BuildLevels(pending, scratchBytes, records);
}

void RayTracingScene::BuildBoxGeometries(const std::vector<BoxGeometry>& geometries, const std::string& what) {
  if (!ctx_) throw Error("crossrt::RayTracingScene::BuildBoxGeometries on a scene without a context");
  if (geometries.size() >= (1u << 24)) throw Error("crossrt::RayTracingScene: " + what + " has more geometries than 24-bit instance ids name");
  for (size_t g = 0; g < geometries.size(); ++g) {
    CheckLeafBoxes(geometries[g].boxes, what + "[" + std::to_string(g) + "]'s leaf");
    if (geometries[g].hitGroup >= (1u << 24))
      throw Error("crossrt::RayTracingScene: the hit group of " + what + "[" + std::to_string(g) + "] does not fit the 24-bit record offset");
  }
  Release();
  const VulkanContext& vk = *ctx_;
  VkDeviceSize scratchBytes = 0;
  std::vector<PendingLevel> pending;
  std::vector<VkAccelerationStructureInstanceKHR> records;
  for (size_t g = 0; g < geometries.size(); ++g) {
    const std::vector<LeafBox>& boxes = geometries[g].boxes;
    if (boxes.empty()) continue;  // no bottom level, no instance: never hit
    std::vector<VkAabbPositionsKHR> aabbs(boxes.size());
    for (size_t i = 0; i < boxes.size(); ++i)
      aabbs[i] = {boxes[i].min[0], boxes[i].min[1], boxes[i].min[2], boxes[i].max[0], boxes[i].max[1], boxes[i].max[2]};
    Buffer input(ctx_, sizeof(VkAabbPositionsKHR) * aabbs.size(), VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
    input.Upload(aabbs.data(), sizeof(VkAabbPositionsKHR) * aabbs.size());
    const VkAccelerationStructureGeometryKHR geometry = AabbGeometry(input.Address());
    pending.push_back(Prepare(geometry, static_cast<uint32_t>(aabbs.size()), scratchBytes));
    pending.back().input = std::move(input);
    auto addressInfo = VkInit<VkAccelerationStructureDeviceAddressInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR);
    addressInfo.accelerationStructure = bottomLevels_.back().handle;
    VkAccelerationStructureInstanceKHR r{};
    for (int a = 0; a < 3; ++a) r.transform.matrix[a][a] = 1.0f;
    r.instanceCustomIndex = static_cast<uint32_t>(g);
    r.mask = 0xFF;
    r.instanceShaderBindingTableRecordOffset = geometries[g].hitGroup;
    r.flags = VK_GEOMETRY_INSTANCE_FORCE_OPAQUE_BIT_KHR;
    r.accelerationStructureReference = vk.vkGetAccelerationStructureDeviceAddressKHR(vk.device, &addressInfo);
    records.push_back(r);
  }
  BuildLevels(pending, scratchBytes, records);
}

void RayTracingScene::BuildLevels(std::vector<PendingLevel>& pending, VkDeviceSize scratchBytes,
                                  const std::vector<VkAccelerationStructureInstanceKHR>& records) {
  const VulkanContext& vk = *ctx_;
  const VkDeviceSize scratchAlign = vk.accelerationScratchAlignment;
  const VkBufferUsageFlags input = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;
  Buffer instanceBuffer(ctx_, sizeof(VkAccelerationStructureInstanceKHR) * std::max<size_t>(1, records.size()), input);
  if (!records.empty()) instanceBuffer.Upload(records.data(), sizeof(records[0]) * records.size());
  auto topGeometry = VkInit<VkAccelerationStructureGeometryKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR);
  topGeometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  topGeometry.geometry.instances = VkInit<VkAccelerationStructureGeometryInstancesDataKHR>(
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR);
  topGeometry.geometry.instances.data.deviceAddress = instanceBuffer.Address();
  auto topBuild = VkInit<VkAccelerationStructureBuildGeometryInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR);
  topBuild.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  topBuild.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  topBuild.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  topBuild.geometryCount = 1;
  topBuild.pGeometries = &topGeometry;
  VkAccelerationStructureBuildRangeInfoKHR topRange{};
  topRange.primitiveCount = static_cast<uint32_t>(records.size());
  auto topSizes = VkInit<VkAccelerationStructureBuildSizesInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR);
  vk.vkGetAccelerationStructureBuildSizesKHR(vk.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &topBuild, &topRange.primitiveCount, &topSizes);
  top_ = Create(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, topSizes.accelerationStructureSize);
  topBuild.dstAccelerationStructure = top_.handle;

  // One scratch buffer: the bottom levels' regions side by side, then reused by the top level.
  Buffer scratch(ctx_, std::max(scratchBytes, topSizes.buildScratchSize) + scratchAlign);
  const VkDeviceAddress scratchBase = AlignUp(scratch.Address(), scratchAlign);
  VkCommandBuffer cmd = ctx_->BeginOneShot();
  for (auto& p : pending) {
    p.build.pGeometries = &p.geometry;  // the vector moved the geometry
    p.build.scratchData.deviceAddress = scratchBase + p.scratchOffset;
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = &p.range;
    vk.vkCmdBuildAccelerationStructuresKHR(cmd, 1, &p.build, &ranges);
  }
  if (!pending.empty())
    BuildBarrier(cmd, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                 VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR);
  topBuild.scratchData.deviceAddress = scratchBase;
  const VkAccelerationStructureBuildRangeInfoKHR* topRanges = &topRange;
  vk.vkCmdBuildAccelerationStructuresKHR(cmd, 1, &topBuild, &topRanges);
  // Read by compute shaders (ray queries) and ray tracing pipelines, whichever the device has: a
  // stage that may not read acceleration structures there would be a validation error.
  const VkPipelineStageFlags readers = (vk.hasRayQuery ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : VkPipelineStageFlags(0)) |
                                       (vk.hasRayTracingPipeline ? VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR : VkPipelineStageFlags(0));
  BuildBarrier(cmd, readers, VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_SHADER_READ_BIT);
  ctx_->SubmitAndWait(cmd);
  topLevel_ = top_.handle;
}

}  // namespace crossrt
