// Pipeline (push-descriptor set 0, arrays of textures, push constants), ComputePipeline, dispatch
// helpers and the barriers generated code puts between dispatches. RayTracingPipeline: RayTracingPipeline.cpp.
#include "crossrt/VulkanRuntime.h"
#include "Internal.h"

#include <utility>

namespace crossrt {

Pipeline::Pipeline(const char* kind, VkPipelineBindPoint bindPoint, VkShaderStageFlags stages, std::shared_ptr<VulkanContext> ctx,
                   std::vector<VkDescriptorType> bindingTypes, uint32_t pushConstantBytes, const char* debugName, uint32_t textureArraySets)
    : ctx_(std::move(ctx)), name_(debugName ? debugName : ""), kind_(kind), bindPoint_(bindPoint), stages_(stages),
      types_(std::move(bindingTypes)), textureArraySets_(textureArraySets), pushConstantBytes_(pushConstantBytes) {
  if (!ctx_) throw Error(Where() + ": null VulkanContext");
  if (textureArraySets_ > 0 && !ctx_->hasTextureArrays)
    throw Error(Where() + ": device '" + ctx_->DeviceName() + "' has no arrays of textures (descriptor indexing)");
  if (pushConstantBytes > ctx_->properties.limits.maxPushConstantsSize || pushConstantBytes % 4 != 0)
    throw Error(Where() + ": " + std::to_string(pushConstantBytes) + " bytes of push constants (must be a multiple of 4 and at most " +
                std::to_string(ctx_->properties.limits.maxPushConstantsSize) + " on this device)");
  VkDevice dev = ctx_->device;
  try {
    if (!types_.empty()) {
      const uint32_t count = static_cast<uint32_t>(types_.size());
      std::vector<VkDescriptorSetLayoutBinding> b(count);
      for (uint32_t i = 0; i < count; ++i) b[i] = VkDescriptorSetLayoutBinding{i, types_[i], 1, stages_, nullptr};
      auto setInfo = VkInit<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
      setInfo.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
      setInfo.bindingCount = count;
      setInfo.pBindings = b.data();
      Check(vkCreateDescriptorSetLayout(dev, &setInfo, nullptr, &setLayout_), "vkCreateDescriptorSetLayout");
    }
    VkPushConstantRange range{stages_, 0, pushConstantBytes_};
    // Set 0 exists whenever later sets do: an empty push-descriptor layout stands in for it.
    if (!setLayout_ && textureArraySets_ > 0) {
      auto setInfo = VkInit<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
      setInfo.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
      Check(vkCreateDescriptorSetLayout(dev, &setInfo, nullptr, &setLayout_), "vkCreateDescriptorSetLayout");
    }
    std::vector<VkDescriptorSetLayout> sets;
    if (setLayout_) sets.push_back(setLayout_);
    for (uint32_t i = 0; i < textureArraySets_; ++i) sets.push_back(ctx_->textureArrayLayout);
    auto layoutInfo = VkInit<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
    layoutInfo.setLayoutCount = static_cast<uint32_t>(sets.size());
    layoutInfo.pSetLayouts = sets.empty() ? nullptr : sets.data();
    layoutInfo.pushConstantRangeCount = pushConstantBytes_ ? 1 : 0;
    layoutInfo.pPushConstantRanges = pushConstantBytes_ ? &range : nullptr;
    Check(vkCreatePipelineLayout(dev, &layoutInfo, nullptr, &layout_), "vkCreatePipelineLayout");
  } catch (...) {
    Release();
    throw;
  }
}

VkShaderModule Pipeline::CreateModule(const uint32_t* spirv, size_t spirvBytes) const {
  if (!spirv || spirvBytes == 0 || spirvBytes % 4 != 0) throw Error(Where() + ": SPIR-V must be a non-empty multiple of 4 bytes");
  auto moduleInfo = VkInit<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
  moduleInfo.codeSize = spirvBytes;
  moduleInfo.pCode = spirv;
  VkShaderModule module = VK_NULL_HANDLE;
  Check(vkCreateShaderModule(ctx_->device, &moduleInfo, nullptr, &module), "vkCreateShaderModule");
  return module;
}

Pipeline::Pipeline(Pipeline&& other) noexcept { *this = std::move(other); }

Pipeline& Pipeline::operator=(Pipeline&& other) noexcept {
  if (this != &other) {
    Release();
    ctx_ = std::move(other.ctx_);
    layout_ = std::exchange(other.layout_, VK_NULL_HANDLE);
    pipeline_ = std::exchange(other.pipeline_, VK_NULL_HANDLE);
    name_ = std::move(other.name_);
    kind_ = other.kind_;
    bindPoint_ = other.bindPoint_;
    stages_ = other.stages_;
    setLayout_ = std::exchange(other.setLayout_, VK_NULL_HANDLE);
    types_ = std::move(other.types_);
    textureArraySets_ = std::exchange(other.textureArraySets_, 0);
    pushConstantBytes_ = std::exchange(other.pushConstantBytes_, 0);
  }
  return *this;
}

Pipeline::~Pipeline() { Release(); }

void Pipeline::Release() noexcept {
  if (ctx_) {
    if (pipeline_) vkDestroyPipeline(ctx_->device, pipeline_, nullptr);
    if (layout_) vkDestroyPipelineLayout(ctx_->device, layout_, nullptr);
    if (setLayout_) vkDestroyDescriptorSetLayout(ctx_->device, setLayout_, nullptr);
  }
  pipeline_ = VK_NULL_HANDLE;
  layout_ = VK_NULL_HANDLE;
  setLayout_ = VK_NULL_HANDLE;
  ctx_.reset();
}

void Pipeline::Bind(VkCommandBuffer cmd) const { vkCmdBindPipeline(cmd, bindPoint_, pipeline_); }

void Pipeline::PushBuffers(VkCommandBuffer cmd, std::initializer_list<BufferView> buffers) const {
  std::vector<Binding> bindings(buffers.begin(), buffers.end());
  Push(cmd, bindings);
}

void Pipeline::PushBindings(VkCommandBuffer cmd, std::initializer_list<Binding> bindings) const {
  Push(cmd, std::vector<Binding>(bindings));
}

void Pipeline::Push(VkCommandBuffer cmd, const std::vector<Binding>& bindings) const {
  const uint32_t count = static_cast<uint32_t>(types_.size());
  if (bindings.size() != count)
    throw Error(Where() + ": got " + std::to_string(bindings.size()) + " resources for " + std::to_string(count) + " bindings");
  if (count == 0) return;
  // Reserved up front: the writes point into these vectors.
  std::vector<VkDescriptorBufferInfo> bufferInfos;
  std::vector<VkDescriptorImageInfo> imageInfos;
  std::vector<VkWriteDescriptorSetAccelerationStructureKHR> sceneInfos;
  bufferInfos.reserve(count);
  imageInfos.reserve(count);
  sceneInfos.reserve(count);
  std::vector<VkWriteDescriptorSet> writes(count);
  for (uint32_t i = 0; i < count; ++i) {
    const Binding& r = bindings[i];
    const std::string where = Where() + ": binding " + std::to_string(i);
    if (r.type != types_[i]) throw Error(where + " got a resource of another descriptor type than its layout's");
    writes[i] = VkInit<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = r.type;
    if (r.type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER) {
      const BufferView& v = r.buffer;
      if (!v.buffer) throw Error(where + " has no buffer");
      // e.g. `vec.data() + k` with k elements not a multiple of the device's offset alignment
      const VkDeviceSize align = ctx_->properties.limits.minStorageBufferOffsetAlignment;
      if (align > 1 && v.offset % align != 0)
        throw Error(where + " starts at byte offset " + std::to_string(v.offset) +
                    ", which this device cannot bind (offsets must be multiples of " + std::to_string(align) +
                    " bytes): use element offsets that keep that alignment");
      bufferInfos.push_back(VkDescriptorBufferInfo{v.buffer, v.offset, v.range});
      writes[i].pBufferInfo = &bufferInfos.back();
    } else if (r.type == VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR) {
      if (!r.accelerationStructure) throw Error(where + " has no acceleration structure (the scene was not built)");
      auto info = VkInit<VkWriteDescriptorSetAccelerationStructureKHR>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR);
      info.accelerationStructureCount = 1;
      info.pAccelerationStructures = &r.accelerationStructure;
      sceneInfos.push_back(info);
      writes[i].pNext = &sceneInfos.back();
    } else {
      if (r.type == VK_DESCRIPTOR_TYPE_SAMPLER ? !r.sampler : !r.view) throw Error(where + " has no image or sampler");
      imageInfos.push_back(VkDescriptorImageInfo{r.sampler, r.view, VK_IMAGE_LAYOUT_GENERAL});
      writes[i].pImageInfo = &imageInfos.back();
    }
  }
  ctx_->vkCmdPushDescriptorSetKHR(cmd, bindPoint_, layout_, 0, count, writes.data());
}

void Pipeline::BindTextureArrays(VkCommandBuffer cmd, std::initializer_list<const TextureArray*> arrays) const {
  if (arrays.size() != textureArraySets_)
    throw Error(Where() + ": got " + std::to_string(arrays.size()) + " arrays of textures for " + std::to_string(textureArraySets_) + " sets");
  std::vector<VkDescriptorSet> sets;
  for (const TextureArray* a : arrays) {
    if (!a || !a->Set()) throw Error(Where() + ": an array of textures was not assigned");
    sets.push_back(a->Set());
  }
  if (!sets.empty())
    vkCmdBindDescriptorSets(cmd, bindPoint_, layout_, 1, static_cast<uint32_t>(sets.size()), sets.data(), 0, nullptr);
}

void Pipeline::PushConstants(VkCommandBuffer cmd, const void* data, uint32_t bytes) const {
  if (bytes > pushConstantBytes_)
    throw Error(Where() + ": " + std::to_string(bytes) + " bytes of push constants, layout has " + std::to_string(pushConstantBytes_));
  if (bytes == 0) return;
  vkCmdPushConstants(cmd, layout_, stages_, 0, bytes, data);
}

// ---- compute pipelines ---------------------------------------------------------------------------

ComputePipeline::ComputePipeline(std::shared_ptr<VulkanContext> ctx, const uint32_t* spirv, size_t spirvBytes,
                                 uint32_t storageBufferBindings, uint32_t pushConstantBytes, const char* debugName,
                                 const std::vector<uint32_t>& constants)
    : ComputePipeline(std::move(ctx), spirv, spirvBytes,
                      std::vector<VkDescriptorType>(storageBufferBindings, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER), pushConstantBytes,
                      debugName, 0, constants) {}

ComputePipeline::ComputePipeline(std::shared_ptr<VulkanContext> ctx, const uint32_t* spirv, size_t spirvBytes,
                                 std::vector<VkDescriptorType> bindingTypes, uint32_t pushConstantBytes, const char* debugName,
                                 uint32_t textureArraySets, const std::vector<uint32_t>& constants)
    : Pipeline("ComputePipeline", VK_PIPELINE_BIND_POINT_COMPUTE, VK_SHADER_STAGE_COMPUTE_BIT, std::move(ctx), std::move(bindingTypes),
               pushConstantBytes, debugName, textureArraySets) {
  try {
    VkShaderModule module = CreateModule(spirv, spirvBytes);
    auto info = VkInit<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
    info.stage = VkInit<VkPipelineShaderStageCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module;
    info.stage.pName = "main";
    const Specialization specialization(ctx_->fenceAtomics, constants);
    info.stage.pSpecializationInfo = &specialization.info;
    info.layout = layout_;
    VkResult r = vkCreateComputePipelines(ctx_->device, ctx_->pipelineCache, 1, &info, nullptr, &pipeline_);
    vkDestroyShaderModule(ctx_->device, module, nullptr);  // the pipeline keeps what it needs
    Check(r, ("vkCreateComputePipelines '" + name_ + "'").c_str());
    ctx_->SetObjectName(VK_OBJECT_TYPE_PIPELINE, reinterpret_cast<uint64_t>(pipeline_), name_.c_str());
  } catch (...) {
    Release();
    throw;
  }
}

// ---- dispatch ------------------------------------------------------------------------------------

namespace {
// Every device supports at least this many groups per dimension; without a context we cannot
// ask for more, and the shader's linear-id formula works with any x.
constexpr uint64_t kMaxGroupsPerDim = 65535;

uint32_t CeilDiv(uint32_t a, uint32_t b) { return static_cast<uint32_t>((uint64_t(a) + b - 1) / b); }  // no overflow

void Split1D(uint64_t threads, uint32_t groupSize, uint32_t& x, uint32_t& y) {
  if (groupSize == 0) throw Error("Dispatch1D: groupSize is 0");
  uint64_t groups = (threads + groupSize - 1) / groupSize;
  if (groups == 0) {
    x = y = 0;
    return;
  }
  uint64_t gy = (groups + kMaxGroupsPerDim - 1) / kMaxGroupsPerDim;
  if (gy > kMaxGroupsPerDim)
    throw Error("Dispatch1D: " + std::to_string(threads) + " threads in groups of " + std::to_string(groupSize) +
                " need more than 65535 x 65535 groups");
  // Balance x over the rows so few groups are wasted (70000 groups -> 35000 x 2).
  uint64_t gx = (groups + gy - 1) / gy;
  x = static_cast<uint32_t>(gx);
  y = static_cast<uint32_t>(gy);
}
}  // namespace

uint32_t GroupCount1D(uint64_t threads, uint32_t groupSize) {
  uint32_t x = 0, y = 0;
  Split1D(threads, groupSize, x, y);
  return x * y;
}

uint32_t Dispatch1D(VkCommandBuffer cmd, uint64_t threads, uint32_t groupSize) {
  uint32_t x = 0, y = 0;
  Split1D(threads, groupSize, x, y);
  if (x * y == 0) return 0;
  vkCmdDispatch(cmd, x, y, 1);
  return x * y;
}

void Dispatch2D(VkCommandBuffer cmd, uint32_t threadsX, uint32_t threadsY, uint32_t groupX, uint32_t groupY) {
  Dispatch3D(cmd, threadsX, threadsY, 1, groupX, groupY, 1);
}

void Dispatch3D(VkCommandBuffer cmd, uint32_t tx, uint32_t ty, uint32_t tz, uint32_t gx, uint32_t gy, uint32_t gz) {
  if (gx == 0 || gy == 0 || gz == 0) throw Error("Dispatch: a group size is 0");
  uint32_t x = CeilDiv(tx, gx), y = CeilDiv(ty, gy), z = CeilDiv(tz, gz);
  if (x == 0 || y == 0 || z == 0) return;  // nothing to do
  vkCmdDispatch(cmd, x, y, z);
}

void ComputeBarrier(VkCommandBuffer cmd) {
  auto b = VkInit<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                    VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &b, 0, nullptr, 0,
                       nullptr);
}

void TransferToComputeBarrier(VkCommandBuffer cmd) {
  auto b = VkInit<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &b, 0, nullptr,
                       0, nullptr);
}

}  // namespace crossrt
