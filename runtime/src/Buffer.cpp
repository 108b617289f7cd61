// Buffer: storage buffers in device-local memory, persistently mapped when that memory is also
// host-visible (lavapipe, resizable-BAR GPUs), otherwise filled/read through a staging buffer;
// read through one too where the mapping is not host-cached (slow to read over PCIe).
#include "crossrt/VulkanRuntime.h"
#include "Internal.h"

#include <cstring>
#include <memory>
#include <mutex>
#include <utility>

namespace crossrt {
// ---- allocation helpers shared with Image.cpp (declared in Internal.h) ----

Allocation Allocate(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage,
                    std::initializer_list<VkMemoryPropertyFlags> preferences) {
  Allocation a;
  auto info = VkInit<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  Check(vkCreateBuffer(ctx.device, &info, nullptr, &a.buffer), "vkCreateBuffer");

  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(ctx.device, a.buffer, &req);
  auto flagsInfo = VkInit<VkMemoryAllocateFlagsInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO);
  flagsInfo.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  auto alloc = VkInit<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
  alloc.allocationSize = req.size;
  if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) alloc.pNext = &flagsInfo;

  VkResult last = VK_ERROR_OUT_OF_DEVICE_MEMORY;
  for (VkMemoryPropertyFlags props : preferences) {
    uint32_t type = ctx.TryFindMemoryType(req.memoryTypeBits, props);
    if (type == UINT32_MAX) continue;
    alloc.memoryTypeIndex = type;
    last = vkAllocateMemory(ctx.device, &alloc, nullptr, &a.memory);
    if (last == VK_SUCCESS) {
      a.flags = ctx.MemoryTypeFlags(type);
      break;
    }
    if (last != VK_ERROR_OUT_OF_DEVICE_MEMORY && last != VK_ERROR_OUT_OF_HOST_MEMORY) break;
  }
  if (last != VK_SUCCESS) {
    vkDestroyBuffer(ctx.device, a.buffer, nullptr);
    Check(last, ("vkAllocateMemory (" + std::to_string(size) + " bytes)").c_str());
  }
  VkResult r = vkBindBufferMemory(ctx.device, a.buffer, a.memory, 0);
  if (r != VK_SUCCESS) {
    vkDestroyBuffer(ctx.device, a.buffer, nullptr);
    vkFreeMemory(ctx.device, a.memory, nullptr);
    Check(r, "vkBindBufferMemory");
  }
  return a;
}

Staging::Staging(const VulkanContext& c, VkDeviceSize bytes, VkBufferUsageFlags usage) : ctx(c), size(bytes) {
  // Cached memory first: downloads read it with the CPU.
  a = Allocate(ctx, size, usage, {kHostCoherent | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, kHostCoherent});
  VkResult r = vkMapMemory(ctx.device, a.memory, 0, VK_WHOLE_SIZE, 0, &mapped);
  if (r != VK_SUCCESS) {
    Free();
    Check(r, "vkMapMemory (staging)");
  }
}

void Staging::Free() {
  vkDestroyBuffer(ctx.device, a.buffer, nullptr);
  vkFreeMemory(ctx.device, a.memory, nullptr);
}

namespace {

void CheckRange(const Buffer& b, size_t bytes, size_t offset, const char* what) {
  if (b.Empty()) throw Error(std::string(what) + ": the buffer is empty (default-constructed or moved-from)");
  if (offset > b.Size() || bytes > b.Size() - offset)
    throw Error(std::string(what) + ": range [" + std::to_string(offset) + ", " + std::to_string(offset + bytes) +
                ") is outside the buffer of " + std::to_string(b.Size()) + " bytes");
}

}  // namespace

Buffer::Buffer(std::shared_ptr<VulkanContext> ctx, VkDeviceSize bytes, VkBufferUsageFlags extraUsage)
    : ctx_(std::move(ctx)), size_(bytes), extraUsage_(extraUsage) {
  if (!ctx_) throw Error("crossrt::Buffer: null VulkanContext");
  VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                             VK_BUFFER_USAGE_TRANSFER_DST_BIT | extraUsage;
  if (ctx_->hasBufferDeviceAddress) usage |= VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  // Never zero (Vulkan forbids it) and a multiple of 16 so Fill covers every byte and
  // vec4/scalar accesses at the tail stay in bounds.
  VkDeviceSize allocSize = ((bytes == 0 ? 1 : bytes) + 15) & ~VkDeviceSize(15);

  const VkMemoryPropertyFlags deviceHost = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | kHostCoherent;
  Allocation a = Allocate(*ctx_, allocSize, usage,
                          {deviceHost, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, kHostCoherent, VkMemoryPropertyFlags(0)});
  buffer_ = a.buffer;
  memory_ = a.memory;
  if (!ctx_->forceStaging && (a.flags & kHostCoherent) == kHostCoherent) {
    VkResult r = vkMapMemory(ctx_->device, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_);
    if (r != VK_SUCCESS) mapped_ = nullptr;  // staging still works
    hostCached_ = mapped_ && (a.flags & VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
  }
  if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) {
    auto info = VkInit<VkBufferDeviceAddressInfo>(VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO);
    info.buffer = buffer_;
    address_ = vkGetBufferDeviceAddress(ctx_->device, &info);
  }
}

Buffer::Buffer(Buffer&& other) noexcept { *this = std::move(other); }

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    Release();
    ctx_ = std::move(other.ctx_);
    buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    size_ = std::exchange(other.size_, 0);
    mapped_ = std::exchange(other.mapped_, nullptr);
    hostCached_ = std::exchange(other.hostCached_, false);
    address_ = std::exchange(other.address_, 0);
    extraUsage_ = std::exchange(other.extraUsage_, 0);
  }
  return *this;
}

Buffer::~Buffer() { Release(); }

void Buffer::Release() noexcept {
  if (ctx_ && buffer_) {
    vkDestroyBuffer(ctx_->device, buffer_, nullptr);
    vkFreeMemory(ctx_->device, memory_, nullptr);  // also unmaps
  }
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
  hostCached_ = false;
  size_ = 0;
  address_ = 0;
  ctx_.reset();
}

// ---- staging buffers reused between copies ----

// One staging buffer per direction, grown to the largest copy so far up to kReusedStagingBytes;
// a larger copy gets a buffer of its own. Allocating (and, on a GPU, pinning) host memory for
// every copy cost more than the copy itself on an NVIDIA H200: LBVH_Vulkan's build of a
// 992-triangle mesh, which reads its nine member vectors back, took 12.8 ms of wall time for
// 0.1 ms on the GPU.
struct VulkanContext::StagingCache {
  static constexpr VkDeviceSize kReusedStagingBytes = VkDeviceSize(64) << 20;
  std::mutex mutex;  // held for a whole copy through a reused buffer
  std::unique_ptr<Staging> upload, download;
};

std::shared_ptr<VulkanContext::StagingCache> MakeStagingCache() { return std::make_shared<VulkanContext::StagingCache>(); }

Staging& StagingFor(const VulkanContext& ctx, VkDeviceSize bytes, VkBufferUsageFlags usage, std::unique_lock<std::mutex>& lock,
                    std::unique_ptr<Staging>& own) {
  VulkanContext::StagingCache* cache = ctx.stagingCache.get();
  if (cache == nullptr || bytes > VulkanContext::StagingCache::kReusedStagingBytes) {
    own = std::make_unique<Staging>(ctx, bytes, usage);
    return *own;
  }
  lock = std::unique_lock<std::mutex>(cache->mutex);
  std::unique_ptr<Staging>& reused = usage == VK_BUFFER_USAGE_TRANSFER_SRC_BIT ? cache->upload : cache->download;
  if (!reused || reused->size < bytes) {
    reused.reset();  // free the smaller one first: holding both could fail where the larger alone fits
    reused = std::make_unique<Staging>(ctx, bytes, usage);
  }
  return *reused;
}

void Buffer::Upload(const void* src, size_t bytes, size_t dstOffset) {
  CheckRange(*this, bytes, dstOffset, "Buffer::Upload");
  if (bytes == 0) return;
  if (mapped_) {
    std::memcpy(static_cast<char*>(mapped_) + dstOffset, src, bytes);  // coherent: no flush needed
    return;
  }
  std::unique_lock<std::mutex> lock;
  std::unique_ptr<Staging> own;
  Staging& staging = StagingFor(*ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, lock, own);
  std::memcpy(staging.mapped, src, bytes);
  VkCommandBuffer cmd = ctx_->BeginOneShot();
  VkBufferCopy region{0, dstOffset, bytes};
  vkCmdCopyBuffer(cmd, staging.a.buffer, buffer_, 1, &region);
  ctx_->SubmitAndWait(cmd);
}

void Buffer::Download(void* dst, size_t bytes, size_t srcOffset) const {
  CheckRange(*this, bytes, srcOffset, "Buffer::Download");
  if (bytes == 0) return;
  Downloads one(ctx_);
  one.Add(*this, dst, bytes, srcOffset);
  one.Run();
}

void Downloads::Add(const Buffer& from, void* to, size_t bytes, size_t srcOffset) {
  CheckRange(from, bytes, srcOffset, "Downloads::Add");
  if (from.ctx_ != ctx_) throw Error("Downloads::Add: the buffer belongs to another Vulkan context");
  copies_.push_back({&from, to, bytes, srcOffset});
}

void Downloads::Run() {
  auto padded = [](size_t bytes) { return VkDeviceSize(bytes + 15) / 16 * 16; };  // each copy's place in the staging buffer
  std::vector<Copy> staged;
  VkDeviceSize total = 0;
  for (const Copy& c : copies_) {
    if (c.bytes == 0) continue;
    if (c.from->mapped_ && c.from->hostCached_)
      std::memcpy(c.to, static_cast<const char*>(c.from->mapped_) + c.srcOffset, c.bytes);
    else {
      staged.push_back(c);
      total += padded(c.bytes);
    }
  }
  copies_.clear();
  if (staged.empty()) return;
  std::unique_lock<std::mutex> lock;
  std::unique_ptr<Staging> own;
  Staging& staging = StagingFor(*ctx_, total, VK_BUFFER_USAGE_TRANSFER_DST_BIT, lock, own);
  VkCommandBuffer cmd = ctx_->BeginOneShot();
  VkDeviceSize at = 0;
  for (const Copy& c : staged) {
    VkBufferCopy region{c.srcOffset, at, c.bytes};
    vkCmdCopyBuffer(cmd, c.from->buffer_, staging.a.buffer, 1, &region);
    at += padded(c.bytes);
  }
  ctx_->SubmitAndWait(cmd);  // ends with a transfer -> host barrier
  at = 0;
  for (const Copy& c : staged) {
    std::memcpy(c.to, static_cast<const char*>(staging.mapped) + at, c.bytes);
    at += padded(c.bytes);
  }
}

void Buffer::Fill(uint32_t value) {
  if (Empty()) throw Error("Buffer::Fill: the buffer is empty (default-constructed or moved-from)");
  VkCommandBuffer cmd = ctx_->BeginOneShot();
  vkCmdFillBuffer(cmd, buffer_, 0, VK_WHOLE_SIZE, value);
  ctx_->SubmitAndWait(cmd);
}

void EnsureSize(std::shared_ptr<VulkanContext> ctx, Buffer& b, VkDeviceSize bytes) {
  if (!b.Empty() && b.Size() >= bytes) return;
  b = Buffer(std::move(ctx), bytes, b.ExtraUsage());
}

void GrowScratch(std::shared_ptr<VulkanContext> ctx, Buffer& b, VkDeviceSize bytes, std::vector<Buffer>& retired) {
  if (!b.Empty() && b.Size() >= bytes) return;
  const VkBufferUsageFlags usage = b.ExtraUsage();
  if (!b.Empty()) retired.push_back(std::move(b));
  b = Buffer(std::move(ctx), bytes, usage);
}

}  // namespace crossrt
