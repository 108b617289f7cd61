// Helpers shared by the runtime's source files (not installed).
#pragma once

#include "crossrt/VulkanRuntime.h"

#include <vulkan/vulkan.h>

#include <initializer_list>
#include <memory>
#include <mutex>
#include <string>

namespace crossrt {

// A zeroed Vulkan struct with its sType set: avoids partial aggregate initialization
// (which -Wextra flags) and forgotten pNext/flags.
template <class T>
T VkInit(VkStructureType sType) {
  T t{};
  t.sType = sType;
  return t;
}

// The specialization every pipeline's shaders get: crt_fenceAtomics (kFenceAtomicsConstantId) from
// the context, then `constants` as kClassConstantIdBase + i (the classes the scene holds, the
// CRT_SPECIALIZE members' values); shaders without a constant ignore it. `info` points into the
// object, which therefore stays where it was made while the pipeline is created.
struct Specialization {
  std::vector<uint32_t> values;
  std::vector<VkSpecializationMapEntry> entries;
  VkSpecializationInfo info{};
  Specialization(bool fence, const std::vector<uint32_t>& constants) {
    values.push_back(fence ? VK_TRUE : VK_FALSE);
    values.insert(values.end(), constants.begin(), constants.end());
    for (uint32_t i = 0; i < values.size(); ++i)
      entries.push_back({i == 0 ? kFenceAtomicsConstantId : kClassConstantIdBase + i - 1, uint32_t(sizeof(uint32_t) * i), sizeof(uint32_t)});
    info = {uint32_t(entries.size()), entries.data(), sizeof(uint32_t) * values.size(), values.data()};
  }
  Specialization(const Specialization&) = delete;
  Specialization& operator=(const Specialization&) = delete;
};

// The optional device features CROSSRT_DEVICE_FEATURES (and ContextOptions::deviceFeatures) hide
// ("-ray_query") or require ("+ray_query"); see DeviceFeatures.cpp.
enum class DeviceFeature { RayQuery, RayTracingPipeline, TextureArrays, FloatAtomics, Count };
struct DeviceFeatureMask {
  bool hidden[size_t(DeviceFeature::Count)] = {};
  bool required[size_t(DeviceFeature::Count)] = {};
  bool Hidden(DeviceFeature f) const { return hidden[size_t(f)]; }
  bool Required(DeviceFeature f) const { return required[size_t(f)]; }
};
const char* DeviceFeatureName(DeviceFeature f);
// Throws Error naming the known features on a word it does not know.
DeviceFeatureMask ParseDeviceFeatures(const std::string& text);

// x rounded up to a multiple of a (a Vulkan alignment; 0 and 1 leave x as it is).
inline VkDeviceSize AlignUp(VkDeviceSize x, VkDeviceSize a) { return a > 1 ? (x + a - 1) / a * a : x; }

// A buffer and its memory: the building block of Buffer and of temporary staging buffers.
struct Allocation {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkMemoryPropertyFlags flags = 0;
};

// Tries the memory property sets in order; falls back to the next one when a heap is full
// (e.g. the 256 MiB BAR window on GPUs without resizable BAR).
Allocation Allocate(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage,
                    std::initializer_list<VkMemoryPropertyFlags> preferences);

constexpr VkMemoryPropertyFlags kHostCoherent = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;

// Host-visible, coherent, mapped temporary buffer, freed on destruction.
struct Staging {
  const VulkanContext& ctx;
  Allocation a;
  void* mapped = nullptr;
  VkDeviceSize size = 0;
  Staging(const VulkanContext& c, VkDeviceSize bytes, VkBufferUsageFlags usage);
  ~Staging() { Free(); }
  void Free();
  Staging(const Staging&) = delete;
  Staging& operator=(const Staging&) = delete;
};

// The reused staging buffers of a context (Buffer.cpp).
std::shared_ptr<VulkanContext::StagingCache> MakeStagingCache();

// A staging buffer for one copy of `bytes` (usage TRANSFER_SRC to upload, TRANSFER_DST to
// download): the context's reused one for the direction, locked by `lock` until the copy is done,
// or `own`, made for this copy where it is larger than the reused ones may grow (Buffer.cpp).
Staging& StagingFor(const VulkanContext& ctx, VkDeviceSize bytes, VkBufferUsageFlags usage, std::unique_lock<std::mutex>& lock,
                    std::unique_ptr<Staging>& own);

}  // namespace crossrt
