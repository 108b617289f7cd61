// CallablePipeline: a ray tracing pipeline (VK_KHR_ray_tracing_pipeline) of one ray generation
// shader, whose threads run a kernel, and the callable shaders its virtual calls execute
// (virtual functions, level 3). It traces no rays: no miss or hit groups.
#include "crossrt/VulkanRuntime.h"
#include "Internal.h"

#include <cstring>
#include <utility>

namespace crossrt {

namespace {
VkDeviceSize AlignUp(VkDeviceSize x, VkDeviceSize a) { return (x + a - 1) / a * a; }

// Checked before the layout is made: its stages exist only on such devices.
std::shared_ptr<VulkanContext> WithRayTracingPipelines(std::shared_ptr<VulkanContext> ctx, const char* debugName) {
  if (ctx && !ctx->hasRayTracingPipeline)
    throw Error(std::string("CallablePipeline '") + (debugName ? debugName : "") + "': device '" + ctx->DeviceName() +
                "' has no ray tracing pipelines (VK_KHR_ray_tracing_pipeline)");
  return ctx;
}
}  // namespace

CallablePipeline::CallablePipeline(std::shared_ptr<VulkanContext> ctx, ShaderCode rayGeneration, const std::vector<ShaderCode>& callables,
                                   std::vector<VkDescriptorType> bindingTypes, uint32_t pushConstantBytes, const char* debugName)
    : Pipeline("CallablePipeline", VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR,
               VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_CALLABLE_BIT_KHR, WithRayTracingPipelines(std::move(ctx), debugName),
               std::move(bindingTypes), pushConstantBytes,
               debugName, 0) {
  std::vector<VkShaderModule> modules;
  try {
    // Stage 0 and group 0: the ray generation shader; stage and group i: callables[i - 1].
    std::vector<VkPipelineShaderStageCreateInfo> stages;
    std::vector<VkRayTracingShaderGroupCreateInfoKHR> groups;
    const FenceSpecialization specialization(ctx_->fenceAtomics);  // kernels with atomics read it
    auto add = [&](ShaderCode code, VkShaderStageFlagBits stage) {
      modules.push_back(CreateModule(code.spirv, code.bytes));
      auto s = VkInit<VkPipelineShaderStageCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
      s.stage = stage;
      s.module = modules.back();
      s.pName = "main";
      s.pSpecializationInfo = &specialization.info;
      stages.push_back(s);
      auto g = VkInit<VkRayTracingShaderGroupCreateInfoKHR>(VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR);
      g.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
      g.generalShader = static_cast<uint32_t>(stages.size() - 1);
      g.closestHitShader = g.anyHitShader = g.intersectionShader = VK_SHADER_UNUSED_KHR;
      groups.push_back(g);
    };
    add(rayGeneration, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    for (const ShaderCode& c : callables) add(c, VK_SHADER_STAGE_CALLABLE_BIT_KHR);

    auto info = VkInit<VkRayTracingPipelineCreateInfoKHR>(VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR);
    info.stageCount = static_cast<uint32_t>(stages.size());
    info.pStages = stages.data();
    info.groupCount = static_cast<uint32_t>(groups.size());
    info.pGroups = groups.data();
    info.maxPipelineRayRecursionDepth = 1;  // callables trace no rays; 1 is the smallest valid value
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
    const VkDeviceSize rayGenBytes = AlignUp(stride, base);
    const VkDeviceSize callableBytes = AlignUp(stride * callables.size(), base);
    // `base` bytes of slack: the buffer's address need only be a multiple of its memory alignment.
    table_ = Buffer(ctx_, base + rayGenBytes + std::max<VkDeviceSize>(callableBytes, base), VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR);
    if (!table_.Address()) throw Error(Where() + ": the shader binding table has no device address");
    const VkDeviceSize start = AlignUp(table_.Address(), base) - table_.Address();
    std::vector<uint8_t> records(table_.Size(), 0);
    std::memcpy(&records[start], handles.data(), handleSize);
    for (size_t i = 0; i < callables.size(); ++i)
      std::memcpy(&records[start + rayGenBytes + i * stride], &handles[(i + 1) * handleSize], handleSize);
    table_.Upload(records.data(), records.size());
    rayGenRegion_ = VkStridedDeviceAddressRegionKHR{table_.Address() + start, rayGenBytes, rayGenBytes};
    if (!callables.empty()) callableRegion_ = VkStridedDeviceAddressRegionKHR{table_.Address() + start + rayGenBytes, stride, callableBytes};
  } catch (...) {
    for (VkShaderModule m : modules) vkDestroyShaderModule(ctx_->device, m, nullptr);
    Release();
    throw;
  }
}

void CallablePipeline::TraceCmd(VkCommandBuffer cmd, uint32_t width, uint32_t height, uint32_t depth) const {
  if (width == 0 || height == 0 || depth == 0) return;
  const VkPipelineStageFlags others = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
  auto b = VkInit<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, others, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, 0, 1, &b, 0, nullptr, 0, nullptr);
  const VkStridedDeviceAddressRegionKHR none{};
  ctx_->vkCmdTraceRaysKHR(cmd, &rayGenRegion_, &none, &none, &callableRegion_, width, height, depth);
  b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, others, 0, 1, &b, 0, nullptr, 0, nullptr);
}

}  // namespace crossrt
