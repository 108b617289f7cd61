// Image and Sampler: what Image2D<T> and LiteImage::Sampler members of a translated class become.
// Images live in device-local memory in VK_IMAGE_LAYOUT_GENERAL: kernels load, store and sample
// them there, so kernels record no transitions. Only the host's copies leave it for a moment.
#include "crossrt/VulkanRuntime.h"
#include "Internal.h"

#include <cstring>
#include <utility>

namespace crossrt {
namespace {

uint32_t TexelBytes(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R32G32B32A32_SFLOAT: return 16;
    case VK_FORMAT_R32_SFLOAT:
    case VK_FORMAT_R32_UINT:
    case VK_FORMAT_R8G8B8A8_UNORM: return 4;
    default: throw Error("crossrt::Image: unsupported format " + std::to_string(int(format)));
  }
}

// A layout change that orders every access before it with every access after it: copies and
// kernels of earlier and later submissions see each other's texels. Copies run in the
// TRANSFER_*_OPTIMAL layouts, which drivers prefer; everything else in GENERAL.
void Transition(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to) {
  auto b = VkInit<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
  b.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0, nullptr, 1,
                       &b);
}

VkBufferImageCopy WholeImage(uint32_t width, uint32_t height) {
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {width, height, 1};
  return region;  // rows tightly packed (bufferRowLength 0)
}

}  // namespace

Image::Image(std::shared_ptr<VulkanContext> ctx, uint32_t width, uint32_t height, VkFormat format, const char* debugName)
    : ctx_(std::move(ctx)), width_(width == 0 ? 1 : width), height_(height == 0 ? 1 : height), format_(format) {
  if (!ctx_) throw Error("crossrt::Image: null VulkanContext");
  const std::string name = debugName ? debugName : "image";
  const uint32_t maxSize = ctx_->properties.limits.maxImageDimension2D;
  if (width_ > maxSize || height_ > maxSize)
    throw Error(name + ": " + std::to_string(width) + " x " + std::to_string(height) + " texels, but device '" +
                ctx_->DeviceName() + "' allows at most " + std::to_string(maxSize) + " per side");
  TexelBytes(format);  // throws for a format the runtime does not copy
  VkDevice dev = ctx_->device;
  try {
    auto info = VkInit<VkImageCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO);
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {width_, height_, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                 VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    Check(vkCreateImage(dev, &info, nullptr, &image_), "vkCreateImage");

    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(dev, image_, &req);
    auto alloc = VkInit<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = ctx_->TryFindMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (alloc.memoryTypeIndex == UINT32_MAX) alloc.memoryTypeIndex = ctx_->FindMemoryType(req.memoryTypeBits, 0);
    Check(vkAllocateMemory(dev, &alloc, nullptr, &memory_), ("vkAllocateMemory (" + name + ")").c_str());
    Check(vkBindImageMemory(dev, image_, memory_, 0), "vkBindImageMemory");

    auto viewInfo = VkInit<VkImageViewCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO);
    viewInfo.image = image_;
    viewInfo.viewType = VK_IMAGE_VIEW_TYPE_2D;
    viewInfo.format = format;
    viewInfo.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    Check(vkCreateImageView(dev, &viewInfo, nullptr, &view_), "vkCreateImageView");
    ctx_->SetObjectName(VK_OBJECT_TYPE_IMAGE, reinterpret_cast<uint64_t>(image_), name.c_str());

    // UNDEFINED -> GENERAL once; the image never leaves GENERAL.
    VkCommandBuffer cmd = ctx_->BeginOneShot();
    auto toGeneral = VkInit<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
    toGeneral.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    toGeneral.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    toGeneral.newLayout = VK_IMAGE_LAYOUT_GENERAL;
    toGeneral.srcQueueFamilyIndex = toGeneral.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    toGeneral.image = image_;
    toGeneral.subresourceRange = viewInfo.subresourceRange;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0, nullptr,
                         1, &toGeneral);
    ctx_->SubmitAndWait(cmd);
  } catch (...) {
    Release();
    throw;
  }
}

Image::Image(Image&& other) noexcept { *this = std::move(other); }

Image& Image::operator=(Image&& other) noexcept {
  if (this != &other) {
    Release();
    ctx_ = std::move(other.ctx_);
    image_ = std::exchange(other.image_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    view_ = std::exchange(other.view_, VK_NULL_HANDLE);
    width_ = std::exchange(other.width_, 0);
    height_ = std::exchange(other.height_, 0);
    format_ = std::exchange(other.format_, VK_FORMAT_UNDEFINED);
  }
  return *this;
}

Image::~Image() { Release(); }

void Image::Release() noexcept {
  if (ctx_) {
    if (view_) vkDestroyImageView(ctx_->device, view_, nullptr);
    if (image_) vkDestroyImage(ctx_->device, image_, nullptr);
    if (memory_) vkFreeMemory(ctx_->device, memory_, nullptr);
  }
  view_ = VK_NULL_HANDLE;
  image_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  ctx_.reset();
}

size_t Image::Bytes() const { return size_t(width_) * height_ * TexelBytes(format_); }

void Image::Upload(const void* texels, size_t bytes) {
  if (Empty()) throw Error("Image::Upload: the image is empty (default-constructed or moved-from)");
  if (bytes != Bytes())
    throw Error("Image::Upload: " + std::to_string(bytes) + " bytes for an image of " + std::to_string(Bytes()) + " bytes");
  std::unique_lock<std::mutex> lock;
  std::unique_ptr<Staging> own;
  Staging& staging = StagingFor(*ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, lock, own);  // the context's, reused
  std::memcpy(staging.mapped, texels, bytes);
  VkCommandBuffer cmd = ctx_->BeginOneShot();
  Transition(cmd, image_, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);  // earlier kernels are done
  const VkBufferImageCopy region = WholeImage(width_, height_);
  vkCmdCopyBufferToImage(cmd, staging.a.buffer, image_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  Transition(cmd, image_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL);  // later kernels see the texels
  ctx_->SubmitAndWait(cmd);
}

void Image::Download(void* texels, size_t bytes) const {
  if (Empty()) throw Error("Image::Download: the image is empty (default-constructed or moved-from)");
  if (bytes != Bytes())
    throw Error("Image::Download: " + std::to_string(bytes) + " bytes for an image of " + std::to_string(Bytes()) + " bytes");
  std::unique_lock<std::mutex> lock;
  std::unique_ptr<Staging> own;
  Staging& staging = StagingFor(*ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, lock, own);  // the context's, reused
  VkCommandBuffer cmd = ctx_->BeginOneShot();
  Transition(cmd, image_, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);  // kernels are done
  const VkBufferImageCopy region = WholeImage(width_, height_);
  vkCmdCopyImageToBuffer(cmd, image_, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.a.buffer, 1, &region);
  Transition(cmd, image_, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL);
  ctx_->SubmitAndWait(cmd);  // ends with a transfer -> host barrier
  std::memcpy(texels, staging.mapped, bytes);
}

void EnsureImage(std::shared_ptr<VulkanContext> ctx, Image& img, uint32_t width, uint32_t height, VkFormat format,
                 const char* debugName) {
  const uint32_t w = width == 0 ? 1 : width, h = height == 0 ? 1 : height;
  if (!img.Empty() && img.Width() == w && img.Height() == h && img.Format() == format) return;
  img = Image(std::move(ctx), w, h, format, debugName);
}

// ---- samplers ----------------------------------------------------------------------------------

Sampler::Sampler(std::shared_ptr<VulkanContext> ctx, const SamplerDesc& desc, const char* debugName)
    : ctx_(std::move(ctx)), desc_(desc) {
  if (!ctx_) throw Error("crossrt::Sampler: null VulkanContext");
  const std::string name = debugName ? debugName : "sampler";
  auto info = VkInit<VkSamplerCreateInfo>(VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO);
  info.magFilter = info.minFilter = desc.linear ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
  info.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  info.addressModeU = desc.addressU;
  info.addressModeV = desc.addressV;
  if ((desc.addressU == VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE || desc.addressV == VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE) &&
      !ctx_->hasMirrorClampToEdge)
    throw Error(name + ": address mode MIRROR_ONCE needs samplerMirrorClampToEdge, which device '" + ctx_->DeviceName() + "' lacks");
  info.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  info.maxLod = 0.0f;  // one mip level, as Image2D has
  const float* c = desc.border;
  const bool borderUsed = desc.addressU == VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER || desc.addressV == VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER;
  if (c[0] == 0 && c[1] == 0 && c[2] == 0 && c[3] == 0)
    info.borderColor = VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK;
  else if (c[0] == 0 && c[1] == 0 && c[2] == 0 && c[3] == 1)
    info.borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_BLACK;
  else if (c[0] == 1 && c[1] == 1 && c[2] == 1 && c[3] == 1)
    info.borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE;
  else if (borderUsed)
    throw Error(name + ": border colour (" + std::to_string(c[0]) + ", " + std::to_string(c[1]) + ", " + std::to_string(c[2]) +
                ", " + std::to_string(c[3]) +
                ") cannot be a Vulkan sampler's: use (0,0,0,0), (0,0,0,1) or (1,1,1,1), or another address mode");
  Check(vkCreateSampler(ctx_->device, &info, nullptr, &sampler_), "vkCreateSampler");
  ctx_->SetObjectName(VK_OBJECT_TYPE_SAMPLER, reinterpret_cast<uint64_t>(sampler_), name.c_str());
}

Sampler::Sampler(Sampler&& other) noexcept { *this = std::move(other); }

Sampler& Sampler::operator=(Sampler&& other) noexcept {
  if (this != &other) {
    Release();
    ctx_ = std::move(other.ctx_);
    sampler_ = std::exchange(other.sampler_, VK_NULL_HANDLE);
    desc_ = other.desc_;
  }
  return *this;
}

Sampler::~Sampler() { Release(); }

void Sampler::Release() noexcept {
  if (ctx_ && sampler_) vkDestroySampler(ctx_->device, sampler_, nullptr);
  sampler_ = VK_NULL_HANDLE;
  ctx_.reset();
}

void EnsureSampler(std::shared_ptr<VulkanContext> ctx, Sampler& s, const SamplerDesc& desc, const char* debugName) {
  if (!s.Empty() && s.Desc() == desc) return;
  s = Sampler(std::move(ctx), desc, debugName);
}

void CheckFilterable(const VulkanContext& ctx, const Image& img, const Sampler& s, const char* what) {
  CheckFilterable(ctx, img.Format(), s.Desc(), what);
}

void CheckFilterable(const VulkanContext& ctx, VkFormat format, const SamplerDesc& s, const char* what) {
  if (!s.linear) return;
  VkFormatProperties props;
  vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice, format, &props);
  if (!(props.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT))
    throw Error(std::string(what) + ": device '" + ctx.DeviceName() +
                "' cannot filter this image's format linearly; sample it with Filter::NEAREST or use another device");
}

}  // namespace crossrt
