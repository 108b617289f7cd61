// RayTracingPipeline: a ray tracing pipeline (VK_KHR_ray_tracing_pipeline) whose ray generation
// shader runs a kernel (virtual functions, level 3): with the callable shaders its virtual calls
// execute, or with the miss shaders and procedural hit groups (intersection + closest hit) of the
// leaves its traversal traces.
#include "crossrt/VulkanRuntime.h"
#include "Internal.h"

#include <algorithm>
#include <cstring>
#include <utility>

namespace crossrt {

namespace {
// The stages a pipeline of these shaders has: its layout makes the bindings visible to all of them.
VkShaderStageFlags StagesOf(const RayTracingShaders& shaders) {
  VkShaderStageFlags stages = VK_SHADER_STAGE_RAYGEN_BIT_KHR;
  if (!shaders.misses.empty()) stages |= VK_SHADER_STAGE_MISS_BIT_KHR;
  if (!shaders.hitGroups.empty()) stages |= VK_SHADER_STAGE_INTERSECTION_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR;
  if (!shaders.callables.empty()) stages |= VK_SHADER_STAGE_CALLABLE_BIT_KHR;
  return stages;
}

// Checked before the layout is made: its stages exist only on such devices.
std::shared_ptr<VulkanContext> WithRayTracingPipelines(std::shared_ptr<VulkanContext> ctx, const char* debugName) {
  if (ctx && !ctx->hasRayTracingPipeline)
    throw Error(std::string("RayTracingPipeline '") + (debugName ? debugName : "") + "': device '" + ctx->DeviceName() +
                "' has no ray tracing pipelines (VK_KHR_ray_tracing_pipeline)");
  return ctx;
}
}  // namespace

RayTracingPipeline::RayTracingPipeline(std::shared_ptr<VulkanContext> ctx, const RayTracingShaders& shaders,
                                       std::vector<VkDescriptorType> bindingTypes, uint32_t pushConstantBytes, const char* debugName,
                                       uint32_t textureArraySets, const std::vector<uint32_t>& constants)
    : Pipeline("RayTracingPipeline", VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, StagesOf(shaders), WithRayTracingPipelines(std::move(ctx), debugName),
               std::move(bindingTypes), pushConstantBytes, debugName, textureArraySets) {
  std::vector<VkShaderModule> modules;
  try {
    // Groups in shader binding table order: the ray generation shader, the misses, the hit groups,
    // the callables.
    std::vector<VkPipelineShaderStageCreateInfo> stages;
    std::vector<VkRayTracingShaderGroupCreateInfoKHR> groups;
    const Specialization specialization(ctx_->fenceAtomics, constants);  // kernels with atomics read the fence switch
    auto stage = [&](ShaderCode code, VkShaderStageFlagBits bit) {
      modules.push_back(CreateModule(code.spirv, code.bytes));
      auto s = VkInit<VkPipelineShaderStageCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
      s.stage = bit;
      s.module = modules.back();
      s.pName = "main";
      s.pSpecializationInfo = &specialization.info;
      stages.push_back(s);
      return static_cast<uint32_t>(stages.size() - 1);
    };
    auto group = [&](VkRayTracingShaderGroupTypeKHR type) {
      auto g = VkInit<VkRayTracingShaderGroupCreateInfoKHR>(VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR);
      g.type = type;
      g.generalShader = g.closestHitShader = g.anyHitShader = g.intersectionShader = VK_SHADER_UNUSED_KHR;
      groups.push_back(g);
      return &groups.back();
    };
    group(VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR)->generalShader = stage(shaders.rayGeneration, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    for (const ShaderCode& c : shaders.misses) group(VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR)->generalShader = stage(c, VK_SHADER_STAGE_MISS_BIT_KHR);
    std::vector<std::pair<const uint32_t*, uint32_t>> closestHits;  // hit groups often share one: a stage each
    for (const RayTracingShaders::HitGroup& h : shaders.hitGroups) {
      const uint32_t intersection = stage(h.intersection, VK_SHADER_STAGE_INTERSECTION_BIT_KHR);
      auto known = std::find_if(closestHits.begin(), closestHits.end(), [&](const auto& c) { return c.first == h.closestHit.spirv; });
      const uint32_t closestHit = known != closestHits.end() ? known->second : stage(h.closestHit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
      if (known == closestHits.end()) closestHits.push_back({h.closestHit.spirv, closestHit});
      auto* g = group(VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR);
      g->intersectionShader = intersection;
      g->closestHitShader = closestHit;
    }
    for (const ShaderCode& c : shaders.callables) group(VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR)->generalShader = stage(c, VK_SHADER_STAGE_CALLABLE_BIT_KHR);

    auto info = VkInit<VkRayTracingPipelineCreateInfoKHR>(VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR);
    info.stageCount = static_cast<uint32_t>(stages.size());
    info.pStages = stages.data();
    info.groupCount = static_cast<uint32_t>(groups.size());
    info.pGroups = groups.data();
    info.maxPipelineRayRecursionDepth = 1;  // only the ray generation shader traces
    info.layout = layout_;
    Check(ctx_->vkCreateRayTracingPipelinesKHR(ctx_->device, VK_NULL_HANDLE, ctx_->pipelineCache, 1, &info, nullptr, &pipeline_),
          ("vkCreateRayTracingPipelinesKHR '" + name_ + "'").c_str());
    for (VkShaderModule m : modules) vkDestroyShaderModule(ctx_->device, m, nullptr);  // the pipeline keeps what it needs
    modules.clear();
    ctx_->SetObjectName(VK_OBJECT_TYPE_PIPELINE, reinterpret_cast<uint64_t>(pipeline_), name_.c_str());

    // The shader binding table: each region starts at a multiple of the base alignment, each
    // record is a group handle padded to the handle alignment.
    const uint32_t handleSize = ctx_->shaderGroupHandleSize;
    std::vector<uint8_t> handles(size_t(handleSize) * groups.size());
    Check(ctx_->vkGetRayTracingShaderGroupHandlesKHR(ctx_->device, pipeline_, 0, static_cast<uint32_t>(groups.size()), handles.size(),
                                                     handles.data()),
          "vkGetRayTracingShaderGroupHandlesKHR");
    const VkDeviceSize base = ctx_->shaderGroupBaseAlignment;
    const VkDeviceSize stride = AlignUp(handleSize, ctx_->shaderGroupHandleAlignment);
    const size_t counts[4] = {1, shaders.misses.size(), shaders.hitGroups.size(), shaders.callables.size()};
    VkDeviceSize offsets[4], total = 0;
    for (int r = 0; r < 4; ++r) {
      offsets[r] = total;
      total += AlignUp(stride * counts[r], base);
    }
    // `base` bytes of slack: the buffer's address need only be a multiple of its memory alignment.
    table_ = Buffer(ctx_, base + std::max(total, base), VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR);
    if (!table_.Address()) throw Error(Where() + ": the shader binding table has no device address");
    const VkDeviceSize start = AlignUp(table_.Address(), base) - table_.Address();
    std::vector<uint8_t> records(table_.Size(), 0);
    size_t handle = 0;
    for (int r = 0; r < 4; ++r)
      for (size_t i = 0; i < counts[r]; ++i, ++handle) std::memcpy(&records[start + offsets[r] + i * stride], &handles[handle * handleSize], handleSize);
    table_.Upload(records.data(), records.size());
    VkStridedDeviceAddressRegionKHR* regions[4] = {&rayGenRegion_, &missRegion_, &hitRegion_, &callableRegion_};
    for (int r = 0; r < 4; ++r)
      if (counts[r] > 0) *regions[r] = VkStridedDeviceAddressRegionKHR{table_.Address() + start + offsets[r], stride, AlignUp(stride * counts[r], base)};
    rayGenRegion_.stride = rayGenRegion_.size;  // the ray generation region's stride must equal its size
  } catch (...) {
    for (VkShaderModule m : modules) vkDestroyShaderModule(ctx_->device, m, nullptr);
    Release();
    throw;
  }
}

void RayTracingPipeline::TraceCmd(VkCommandBuffer cmd, uint32_t width, uint32_t height, uint32_t depth) const {
  if (width == 0 || height == 0 || depth == 0) return;
  const VkPipelineStageFlags others = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
  auto b = VkInit<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, others, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, 0, 1, &b, 0, nullptr, 0, nullptr);
  ctx_->vkCmdTraceRaysKHR(cmd, &rayGenRegion_, &missRegion_, &hitRegion_, &callableRegion_, width, height, depth);
  b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, others, 0, 1, &b, 0, nullptr, 0, nullptr);
}

}  // namespace crossrt
