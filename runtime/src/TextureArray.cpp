// TextureArray: an array of combined image samplers in a descriptor set of its own, for kernels
// that sample std::vector<LiteImage::Texture2D<T>> members on devices with descriptor indexing.
#include "crossrt/VulkanRuntime.h"
#include "Internal.h"

#include <utility>

namespace crossrt {

TextureArray::TextureArray(std::shared_ptr<VulkanContext> ctx, const char* debugName)
    : ctx_(std::move(ctx)), name_(debugName ? debugName : "textures") {
  if (!ctx_) throw Error("crossrt::TextureArray: null VulkanContext");
  if (!ctx_->hasTextureArrays)
    throw Error(name_ + ": device '" + ctx_->DeviceName() + "' has no arrays of textures (descriptor indexing)");
}

TextureArray::TextureArray(TextureArray&& other) noexcept { *this = std::move(other); }

TextureArray& TextureArray::operator=(TextureArray&& other) noexcept {
  if (this != &other) {
    Release();
    ctx_ = std::move(other.ctx_);
    name_ = std::move(other.name_);
    images_ = std::move(other.images_);
    samplers_ = std::move(other.samplers_);
    pool_ = std::exchange(other.pool_, VK_NULL_HANDLE);
    set_ = std::exchange(other.set_, VK_NULL_HANDLE);
  }
  return *this;
}

TextureArray::~TextureArray() { Release(); }

void TextureArray::Release() noexcept {
  if (ctx_ && pool_) vkDestroyDescriptorPool(ctx_->device, pool_, nullptr);  // frees the set
  pool_ = VK_NULL_HANDLE;
  set_ = VK_NULL_HANDLE;
  images_.clear();
  samplers_.clear();
}

void TextureArray::Assign(VkFormat format, const std::vector<Texture>& textures) {
  if (!ctx_) throw Error("TextureArray::Assign: the array has no context (default-constructed or moved-from)");
  if (textures.size() > ctx_->maxTextureArraySize)
    throw Error(name_ + ": " + std::to_string(textures.size()) + " textures, but device '" + ctx_->DeviceName() + "' binds at most " +
                std::to_string(ctx_->maxTextureArraySize) + " in an array");
  // One format for all: checked once, before the old set goes.
  for (size_t i = 0; i < textures.size(); ++i)
    if (textures[i].sampler.linear) {
      CheckFilterable(*ctx_, format, textures[i].sampler, (name_ + "[" + std::to_string(i) + "]").c_str());
      break;
    }
  // Kernels may still sample the old set: let them finish before it goes.
  vkDeviceWaitIdle(ctx_->device);
  Release();
  // A set of variable size holds at least one descriptor: an empty array binds one 1 x 1 image.
  const uint32_t count = textures.empty() ? 1 : static_cast<uint32_t>(textures.size());
  std::vector<uint32_t> samplerOf(count, 0);
  for (uint32_t i = 0; i < count; ++i) {
    const Texture t = textures.empty() ? Texture{} : textures[i];
    const std::string name = name_ + "[" + std::to_string(i) + "]";
    images_.emplace_back(ctx_, t.width, t.height, format, name.c_str());
    if (t.width > 0 && t.height > 0) images_.back().Upload(t.texels, images_.back().Bytes());
    size_t s = 0;
    while (s < samplers_.size() && samplers_[s].Desc() != t.sampler) ++s;
    if (s == samplers_.size()) samplers_.emplace_back(ctx_, t.sampler, (name + " sampler").c_str());
    samplerOf[i] = static_cast<uint32_t>(s);
  }

  const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, count};
  auto poolInfo = VkInit<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
  poolInfo.maxSets = 1;
  poolInfo.poolSizeCount = 1;
  poolInfo.pPoolSizes = &size;
  Check(vkCreateDescriptorPool(ctx_->device, &poolInfo, nullptr, &pool_), "vkCreateDescriptorPool (arrays of textures)");
  auto variable = VkInit<VkDescriptorSetVariableDescriptorCountAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_VARIABLE_DESCRIPTOR_COUNT_ALLOCATE_INFO);
  variable.descriptorSetCount = 1;
  variable.pDescriptorCounts = &count;
  auto alloc = VkInit<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
  alloc.pNext = &variable;
  alloc.descriptorPool = pool_;
  alloc.descriptorSetCount = 1;
  alloc.pSetLayouts = &ctx_->textureArrayLayout;
  Check(vkAllocateDescriptorSets(ctx_->device, &alloc, &set_), "vkAllocateDescriptorSets (arrays of textures)");

  std::vector<VkDescriptorImageInfo> infos(count);
  for (uint32_t i = 0; i < count; ++i) infos[i] = {samplers_[samplerOf[i]].Handle(), images_[i].View(), VK_IMAGE_LAYOUT_GENERAL};
  auto write = VkInit<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
  write.dstSet = set_;
  write.dstBinding = 0;
  write.descriptorCount = count;
  write.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  write.pImageInfo = infos.data();
  vkUpdateDescriptorSets(ctx_->device, 1, &write, 0, nullptr);
}

}  // namespace crossrt
