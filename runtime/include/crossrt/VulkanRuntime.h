// CrossRT Vulkan runtime: the small layer that translator-generated code links to.
// It creates a compute-capable device, allocates storage buffers, builds compute pipelines from
// embedded SPIR-V (push descriptors + push constants), dispatches, and times GPU work.
#pragma once

#include "crossrt/ClassName.h"
#include "SortKey.h"

#include <vulkan/vulkan.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <cstring>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <vector>

namespace crossrt {

// The specialization constant id of the generated kernels' crt_fenceAtomics (VulkanContext::fenceAtomics);
// the translator writes it into the shaders, and generated classes static_assert that it matches.
constexpr uint32_t kFenceAtomicsConstantId = 1700;

// Shaders specialised to the scene, from specialization constant kClassConstantIdBase on. First the
// virtual calls': constant kClassConstantIdBase + i of a generated kernel is true while the objects
// its virtual calls reach include one of class i (the generated class numbers the (vector, class)
// pairs); a switch case whose constant is false is dead code, which the driver removes from the
// pipeline. Then one per CRT_SPECIALIZE member (Specialize.h) the kernels read, holding its value.
// A pipeline gets them all as one vector of 32-bit values (ComputePipeline, RayTracingPipeline).
constexpr uint32_t kClassConstantIdBase = 1800;

// A CRT_SPECIALIZE member's value as its specialization constant holds it: 32 bits, a bool as VkBool32.
template <class T>
uint32_t SpecializationValue(T value) {
  static_assert(sizeof(T) == 4 || std::is_same_v<T, bool>, "specialization constants hold bools and 32-bit values");
  if constexpr (std::is_same_v<T, bool>) {
    return value ? 1u : 0u;
  } else {
    uint32_t bits = 0;
    std::memcpy(&bits, &value, sizeof(bits));
    return bits;
  }
}

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Thrown when no Vulkan driver/device exists at all, so callers (tests, tools) can tell
// "this machine cannot run Vulkan" apart from real failures.
struct NoDeviceError : Error {
  using Error::Error;
};

// How a generated class runs a control function's thread loop that calls several kernels:
// one dispatch per kernel call, each thread's locals kept in buffers between them (Wavefront), or
// the whole loop body as one shader, locals in registers (Megakernel).
enum class ExecutionMode { Wavefront, Megakernel };

// Throws Error("<what> failed: VK_ERROR_... (code)") unless r == VK_SUCCESS.
void Check(VkResult r, const char* what);
// Name of a VkResult, e.g. "VK_ERROR_DEVICE_LOST".
const char* ResultName(VkResult r);

struct ContextOptions {
  std::string device;        // "" = automatic; else a device index ("1") or a case-insensitive substring of the name
  bool validation = false;   // enable VK_LAYER_KHRONOS_validation + VK_EXT_debug_utils messenger
  // Enabled when present: by default what ray queries and ray tracing pipelines need
  // (hasRayQuery and hasRayTracingPipeline tell whether they are on).
  // And atomic adds of floats in buffers (hasFloatAtomicAdd), which InterlockedAdd and ReduceAdd of floats need.
  std::vector<const char*> optionalDeviceExtensions = {VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME,
                                                       VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                                       VK_KHR_RAY_QUERY_EXTENSION_NAME,
                                                       VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME,
                                                       VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME};
  // Testing aid: never map device buffers, so Upload/Download take the staging path that GPUs
  // without host-visible VRAM need (lavapipe's memory is always host-visible).
  bool forceStaging = false;
  // Optional features to hide ("-ray_query") or require ("+ray_query"), comma-separated: ray_query,
  // ray_tracing_pipeline, texture_arrays, float_atomics. A hidden feature is not enabled, so
  // generated classes take the path a device without it takes; a required one the device lacks
  // makes Create throw. The environment's CROSSRT_DEVICE_FEATURES is applied after these.
  std::string deviceFeatures;
};

class VulkanContext {
public:
  // Reads CROSSRT_DEVICE (index or name substring) and CROSSRT_VALIDATION=1.
  // Automatic choice: discrete GPU > integrated > virtual > CPU (lavapipe).
  static std::shared_ptr<VulkanContext> CreateDefault();
  static std::shared_ptr<VulkanContext> Create(const ContextOptions& options);
  ~VulkanContext();  // waits idle, saves the pipeline cache, destroys everything
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t queueFamily = 0;
  VkCommandPool commandPool = VK_NULL_HANDLE;
  VkPipelineCache pipelineCache = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties{};  // limits, name, timestampPeriod
  bool hasScalarBlockLayout = false, hasBufferDeviceAddress = false, hasRayQuery = false,
       hasShaderFloat64 = false, hasShaderInt64 = false;
  bool hasFloatAtomicAdd = false;  // atomicAdd of 32-bit floats in storage buffers (VK_EXT_shader_atomic_float)
  // Ray tracing pipelines (VK_KHR_ray_tracing_pipeline, with acceleration structures and buffer
  // device addresses): what RayTracingPipeline needs, the pipeline virtual functions run in at
  // level 3. Then the shader group handle limits follow.
  bool hasRayTracingPipeline = false;
  uint32_t shaderGroupHandleSize = 0, shaderGroupHandleAlignment = 1, shaderGroupBaseAlignment = 1;
  // Arrays of combined image samplers indexed per thread (descriptor indexing: runtime arrays,
  // non-uniform indexing, partially bound sets of variable size). Then textureArrayLayout is the
  // set layout of one such array, of up to maxTextureArraySize textures.
  bool hasTextureArrays = false;
  uint32_t maxTextureArraySize = 0;
  // Samplers that mirror once, then clamp (LiteImage's MIRROR_ONCE): Vulkan 1.2's samplerMirrorClampToEdge.
  bool hasMirrorClampToEdge = false;
  VkDescriptorSetLayout textureArrayLayout = VK_NULL_HANDLE;
  // Subgroups of compute shaders: generated reductions need arithmetic ops and >= 4 lanes.
  uint32_t subgroupSize = 0;
  bool hasSubgroupArithmetic = false;
  bool forceStaging = false;  // see ContextOptions::forceStaging
  // The staging buffers that Buffer::Upload and Download reuse (runtime/src/Buffer.cpp).
  struct StagingCache;
  std::shared_ptr<StagingCache> stagingCache;
  // Kernels that call crossrt atomics fence them (memoryBarrierBuffer) for acquire-release order,
  // under the specialization constant kFenceAtomicsConstantId, which every pipeline's shaders get
  // from here. Off on llvmpipe: its atomics are sequentially consistent already, and its memory
  // barriers inside loops that threads leave at different times give wrong results (Mesa 22.3).
  bool fenceAtomics = true;
  // The iterations a shader invocation may run through all its loops together before the device ends
  // them, 0 for no limit. llvmpipe counts every loop's back edges in one counter per invocation and
  // leaves all loops at 65535 (Mesa's LP_MAX_TGSI_LOOP_ITERATIONS), silently: a megakernel that loops
  // over many samples, bounces and traversal steps there must split its work into smaller dispatches.
  uint32_t loopIterationLimit = 0;

  std::string DeviceName() const;

  // Validation: WARNING/ERROR messages received by the debug messenger (thread-safe).
  size_t ValidationMessageCount() const;
  std::vector<std::string> ValidationMessages() const;
  void ClearValidationMessages();

  PFN_vkCmdPushDescriptorSetKHR vkCmdPushDescriptorSetKHR = nullptr;
  // VK_KHR_acceleration_structure (not exported by the loader), loaded when hasRayQuery.
  PFN_vkGetAccelerationStructureBuildSizesKHR vkGetAccelerationStructureBuildSizesKHR = nullptr;
  PFN_vkCreateAccelerationStructureKHR vkCreateAccelerationStructureKHR = nullptr;
  PFN_vkDestroyAccelerationStructureKHR vkDestroyAccelerationStructureKHR = nullptr;
  PFN_vkCmdBuildAccelerationStructuresKHR vkCmdBuildAccelerationStructuresKHR = nullptr;
  PFN_vkGetAccelerationStructureDeviceAddressKHR vkGetAccelerationStructureDeviceAddressKHR = nullptr;
  VkDeviceSize accelerationScratchAlignment = 1;  // minAccelerationStructureScratchOffsetAlignment
  // VK_KHR_ray_tracing_pipeline, loaded when hasRayTracingPipeline.
  PFN_vkCreateRayTracingPipelinesKHR vkCreateRayTracingPipelinesKHR = nullptr;
  PFN_vkGetRayTracingShaderGroupHandlesKHR vkGetRayTracingShaderGroupHandlesKHR = nullptr;
  PFN_vkCmdTraceRaysKHR vkCmdTraceRaysKHR = nullptr;

  // One-shot command buffers come from the shared commandPool: allocation, submission and freeing
  // are locked, but Vulkan pools allow recording from only one thread at a time.
  VkCommandBuffer BeginOneShot();           // allocate + begin a primary command buffer
  // End, submit, wait on a fence, free. Ends with a device->host memory barrier, so mapped
  // buffers can be read right after.
  void SubmitAndWait(VkCommandBuffer cmd);
  // Index of a memory type in typeBits having all of props; throws Error if there is none.
  uint32_t FindMemoryType(uint32_t typeBits, VkMemoryPropertyFlags props) const;
  // Same, but returns UINT32_MAX instead of throwing.
  uint32_t TryFindMemoryType(uint32_t typeBits, VkMemoryPropertyFlags props) const;
  VkMemoryPropertyFlags MemoryTypeFlags(uint32_t typeIndex) const;
  // Names an object for validation messages and debuggers; no-op without VK_EXT_debug_utils.
  void SetObjectName(VkObjectType type, uint64_t handle, const char* name) const;

private:
  VulkanContext() = default;
  void Init(const ContextOptions& options);
  void CreateInstance(const ContextOptions& options);
  void CreateDevice(const ContextOptions& options);
  void LoadPipelineCache();
  void SavePipelineCache();
  static VKAPI_ATTR VkBool32 VKAPI_CALL DebugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                      VkDebugUtilsMessageTypeFlagsEXT types,
                                                      const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                      void* user);

  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  PFN_vkSetDebugUtilsObjectNameEXT setObjectName_ = nullptr;
  VkPhysicalDeviceMemoryProperties memoryProperties_{};
  std::string pipelineCachePath_;
  mutable std::mutex messagesMutex_;
  std::vector<std::string> messages_;
  std::mutex submitMutex_;  // command pool and queue need external synchronization
};

struct BufferView {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceSize offset = 0;
  VkDeviceSize range = VK_WHOLE_SIZE;
};

// RAII storage buffer, move-only.
// Usage: STORAGE | TRANSFER_SRC | TRANSFER_DST (+ SHADER_DEVICE_ADDRESS if supported) | extraUsage.
class Buffer {
public:
  Buffer() = default;
  Buffer(std::shared_ptr<VulkanContext> ctx, VkDeviceSize bytes, VkBufferUsageFlags extraUsage = 0);
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  ~Buffer();

  VkBuffer Handle() const { return buffer_; }
  VkDeviceSize Size() const { return size_; }  // bytes requested (the allocation may be larger)
  bool Empty() const { return buffer_ == VK_NULL_HANDLE; }
  BufferView View(VkDeviceSize offset = 0, VkDeviceSize range = VK_WHOLE_SIZE) const {
    return BufferView{buffer_, offset, range};
  }
  VkBufferUsageFlags ExtraUsage() const { return extraUsage_; }
  bool HostMapped() const { return mapped_ != nullptr; }

  // Mapped memcpy if host-visible, else staging buffer + one-shot copy (synchronous). Download
  // reads mapped memory only if it is also host-cached: a discrete GPU's device-local memory
  // seen through the PCIe BAR reads at tens of MB/s (seen on an H100), a staging copy at GB/s.
  void Upload(const void* src, size_t bytes, size_t dstOffset = 0);
  void Download(void* dst, size_t bytes, size_t srcOffset = 0) const;
  void Fill(uint32_t value);         // vkCmdFillBuffer over the whole buffer, one-shot
  VkDeviceAddress Address() const { return address_; }  // 0 if unsupported

private:
  friend class Downloads;
  void Release() noexcept;

  std::shared_ptr<VulkanContext> ctx_;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
  bool hostCached_ = false;  // mapped_ is also fast to read
  VkDeviceAddress address_ = 0;
  VkBufferUsageFlags extraUsage_ = 0;
};

// RAII 2D image with one mip level, move-only: what Image2D<T> members become. Kernels find it in
// VK_IMAGE_LAYOUT_GENERAL and load, store and sample it there; only Upload and Download leave it
// (for the transfer layouts) and return.
// Usage: STORAGE | SAMPLED | TRANSFER_SRC | TRANSFER_DST.
class Image {
public:
  Image() = default;
  // width and height of 0 become 1 (Vulkan has no empty images).
  Image(std::shared_ptr<VulkanContext> ctx, uint32_t width, uint32_t height, VkFormat format, const char* debugName);
  Image(Image&& other) noexcept;
  Image& operator=(Image&& other) noexcept;
  Image(const Image&) = delete;
  Image& operator=(const Image&) = delete;
  ~Image();

  bool Empty() const { return image_ == VK_NULL_HANDLE; }
  uint32_t Width() const { return width_; }
  uint32_t Height() const { return height_; }
  VkFormat Format() const { return format_; }
  VkImage Handle() const { return image_; }
  VkImageView View() const { return view_; }
  size_t Bytes() const;  // of its texels, tightly packed
  // Whole-image copies of tightly packed rows (synchronous, through a staging buffer). Upload
  // ends with a barrier, so later kernels see the texels.
  void Upload(const void* texels, size_t bytes);
  void Download(void* texels, size_t bytes) const;

private:
  void Release() noexcept;

  std::shared_ptr<VulkanContext> ctx_;
  VkImage image_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
  uint32_t width_ = 0, height_ = 0;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
};

// The image a kernel's Image2D parameter is given: a device image and the size of the host image
// it copies (0 x 0 for an empty one, whose device image has one texel). width() and height() are
// spelled as LiteImage spells them, so that a kernel's thread count written with them compiles in
// the generated host code too.
struct ImageView {
  ImageView() = default;
  ImageView(const Image& img, uint32_t width, uint32_t height)
      : view(img.View()), format(img.Format()), imageWidth(width), imageHeight(height) {}
  uint32_t width() const { return imageWidth; }
  uint32_t height() const { return imageHeight; }

  VkImageView view = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  uint32_t imageWidth = 0, imageHeight = 0;
};

// Reallocates img when it is empty or has another size or format.
void EnsureImage(std::shared_ptr<VulkanContext> ctx, Image& img, uint32_t width, uint32_t height, VkFormat format,
                 const char* debugName);

// What a LiteImage::Sampler asks of the GPU. Vulkan samplers know three border colours: a border
// colour other than (0,0,0,0), (0,0,0,1) or (1,1,1,1) is an error when the sampler is created.
struct SamplerDesc {
  bool linear = false;
  VkSamplerAddressMode addressU = VK_SAMPLER_ADDRESS_MODE_REPEAT, addressV = VK_SAMPLER_ADDRESS_MODE_REPEAT;
  float border[4] = {0, 0, 0, 0};
  bool operator==(const SamplerDesc& o) const {
    return linear == o.linear && addressU == o.addressU && addressV == o.addressV && border[0] == o.border[0] &&
           border[1] == o.border[1] && border[2] == o.border[2] && border[3] == o.border[3];
  }
  bool operator!=(const SamplerDesc& o) const { return !(*this == o); }
};

// The SamplerDesc of a LiteImage::Sampler (any type with its fields and enums: the runtime does
// not depend on LiteImage).
template <typename Mode>
VkSamplerAddressMode AddressModeOf(Mode m) {
  switch (m) {
    case Mode::MIRROR: return VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT;
    case Mode::CLAMP: return VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    case Mode::BORDER: return VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER;
    case Mode::MIRROR_ONCE: return VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE;  // needs samplerMirrorClampToEdge
    default: return VK_SAMPLER_ADDRESS_MODE_REPEAT;
  }
}
template <typename LiteSampler>
SamplerDesc DescribeSampler(const LiteSampler& s) {
  SamplerDesc d;
  d.linear = s.filter == LiteSampler::Filter::LINEAR;
  d.addressU = AddressModeOf(s.addressU);
  d.addressV = AddressModeOf(s.addressV);
  d.border[0] = s.borderColor.x;
  d.border[1] = s.borderColor.y;
  d.border[2] = s.borderColor.z;
  d.border[3] = s.borderColor.w;
  return d;
}

// RAII sampler, move-only: what LiteImage::Sampler members become. Nearest or linear filtering,
// one mip level, normalized coordinates (texel centres at (i + 0.5) / size, as on the CPU).
class Sampler {
public:
  Sampler() = default;
  Sampler(std::shared_ptr<VulkanContext> ctx, const SamplerDesc& desc, const char* debugName);
  Sampler(Sampler&& other) noexcept;
  Sampler& operator=(Sampler&& other) noexcept;
  Sampler(const Sampler&) = delete;
  Sampler& operator=(const Sampler&) = delete;
  ~Sampler();

  bool Empty() const { return sampler_ == VK_NULL_HANDLE; }
  VkSampler Handle() const { return sampler_; }
  const SamplerDesc& Desc() const { return desc_; }

private:
  void Release() noexcept;
  std::shared_ptr<VulkanContext> ctx_;
  VkSampler sampler_ = VK_NULL_HANDLE;
  SamplerDesc desc_;
};

// Recreates s when it is empty or describes another sampler.
void EnsureSampler(std::shared_ptr<VulkanContext> ctx, Sampler& s, const SamplerDesc& desc, const char* debugName);
// Throws when a kernel samples img with linear filtering that its format cannot filter.
void CheckFilterable(const VulkanContext& ctx, const Image& img, const Sampler& s, const char* what);
void CheckFilterable(const VulkanContext& ctx, VkFormat format, const SamplerDesc& s, const char* what);

// Acceleration structures (VK_KHR_acceleration_structure), move-only: what an ISceneObject member
// becomes for the shaders that trace on ray tracing hardware (Build: one bottom level per triangle
// mesh, one top level over the instances, both built on the device), or the leaves of a composed
// traversal whose intersection shaders a ray tracing pipeline runs (BuildLeaves).
// In a hit on what Build made, the instance index is the instance's position in `instances` and the
// custom index its mesh; the primitive index is the triangle's position in its mesh. In BuildLeaves'
// scene, the instance index and the custom index are the leaf's.
class RayTracingScene {
public:
  struct Mesh {
    const float* triangles = nullptr;  // 9 floats per triangle: corners v0, v1, v2
    size_t triangleCount = 0;
  };
  struct Instance {
    uint32_t mesh = 0;            // index into the meshes given to Build
    float toWorldRows[12] = {};   // rows 0-2 of the object-to-world matrix, row-major
  };

  RayTracingScene() = default;
  // Throws unless the device has acceleration structures (ray queries or ray tracing pipelines).
  explicit RayTracingScene(std::shared_ptr<VulkanContext> ctx);
  RayTracingScene(RayTracingScene&& other) noexcept;
  RayTracingScene& operator=(RayTracingScene&& other) noexcept;
  RayTracingScene(const RayTracingScene&) = delete;
  RayTracingScene& operator=(const RayTracingScene&) = delete;
  ~RayTracingScene();

  // Replaces what was built (synchronous). Instances of empty meshes are kept but never hit, so
  // instance indices stay; an empty scene is a top level that every ray misses.
  void Build(const std::vector<Mesh>& meshes, const std::vector<Instance>& instances);

  // Leaves of a traversal whose intersection shaders the ray tracing pipeline runs: one instance
  // per box, in order (gl_InstanceID is the box's index), each with the shader binding table offset
  // of its hit group, over one bottom level holding a unit box. A box that is flat along an axis is
  // given a sliver of thickness there. Throws on boxes with NaN or min > max, naming `what`.
  struct LeafBox {
    float min[3], max[3];
    uint32_t hitGroup;
  };
  void BuildLeaves(const std::vector<LeafBox>& leaves, const std::string& what);
  static void CheckLeafBoxes(const std::vector<LeafBox>& leaves, const std::string& what);  // BuildLeaves' check, alone

  // Leaves of a traversal in the paper's form (listing 2: Intersect(ray, CRT_LeafInfo, hit, ...)
  // per leaf box of a geometry): a bottom level per geometry over its boxes (gl_PrimitiveID is the
  // box's index), and an instance of it, untransformed, whose custom index is the geometry's index
  // and whose record offset is its hit group. A geometry without boxes has no instance: never hit. Throws on boxes with NaN or min > max, naming `what`.
  struct BoxGeometry {
    std::vector<LeafBox> boxes;  // their hitGroup is not used
    uint32_t hitGroup = 0;
  };
  void BuildBoxGeometries(const std::vector<BoxGeometry>& geometries, const std::string& what);
  bool Empty() const { return topLevel_ == VK_NULL_HANDLE; }
  VkAccelerationStructureKHR TopLevel() const { return topLevel_; }

private:
  struct Level {
    VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
    Buffer storage;
  };
  struct PendingLevel;  // a bottom level created, waiting for its build
  Level Create(VkAccelerationStructureTypeKHR type, VkDeviceSize bytes);
  // Sizes and creates a bottom level for `geometry` (primitiveCount primitives), to build later.
  PendingLevel Prepare(const VkAccelerationStructureGeometryKHR& geometry, uint32_t primitiveCount, VkDeviceSize& scratchBytes);
  // Builds the pending bottom levels, then the top level over `records` (synchronous).
  void BuildLevels(std::vector<PendingLevel>& pending, VkDeviceSize scratchBytes, const std::vector<VkAccelerationStructureInstanceKHR>& records);
  void Release() noexcept;

  std::shared_ptr<VulkanContext> ctx_;
  std::vector<Level> bottomLevels_;  // one per non-empty mesh
  Level top_;
  VkAccelerationStructureKHR topLevel_ = VK_NULL_HANDLE;
};

// One descriptor of a kernel's push-descriptor set: a storage buffer (converts from BufferView),
// a storage image, a sampled image, a sampler or a top-level acceleration structure.
struct Binding {
  Binding(BufferView b) : type(VK_DESCRIPTOR_TYPE_STORAGE_BUFFER), buffer(b) {}
  static Binding StorageImage(const Image& img) { return Binding(VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, img.View(), VK_NULL_HANDLE); }
  static Binding SampledImage(const Image& img) { return Binding(VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, img.View(), VK_NULL_HANDLE); }
  static Binding StorageImage(const ImageView& img) { return Binding(VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, img.view, VK_NULL_HANDLE); }
  static Binding SampledImage(const ImageView& img) { return Binding(VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, img.view, VK_NULL_HANDLE); }
  static Binding SamplerOf(const Sampler& s) { return Binding(VK_DESCRIPTOR_TYPE_SAMPLER, VK_NULL_HANDLE, s.Handle()); }
  static Binding SceneOf(const RayTracingScene& scene) {
    Binding b(VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, VK_NULL_HANDLE, VK_NULL_HANDLE);
    b.accelerationStructure = scene.TopLevel();
    return b;
  }

  VkDescriptorType type;
  BufferView buffer;
  VkImageView view = VK_NULL_HANDLE;
  VkSampler sampler = VK_NULL_HANDLE;
  VkAccelerationStructureKHR accelerationStructure = VK_NULL_HANDLE;

private:
  Binding(VkDescriptorType t, VkImageView v, VkSampler s) : type(t), view(v), sampler(s) {}
};

// Buffer::Download for several buffers at once: the copies that go through a staging buffer share
// one, recorded in one command buffer, with one submit and one wait (a generated class reads the
// member vectors a control function wrote back so: LBVH_Vulkan's build reads nine).
class Downloads {
 public:
  explicit Downloads(std::shared_ptr<VulkanContext> ctx) : ctx_(std::move(ctx)) {}
  // `bytes` of `from` at `srcOffset` to `to`, when Run() is called (a buffer of this context).
  void Add(const Buffer& from, void* to, size_t bytes, size_t srcOffset = 0);
  // All copies added since the last Run.
  void Run();

 private:
  struct Copy {
    const Buffer* from;
    void* to;
    size_t bytes, srcOffset;
  };
  std::shared_ptr<VulkanContext> ctx_;
  std::vector<Copy> copies_;
};

// The object a composed member (shared_ptr, unique_ptr or plain pointer) holds, or null.
template <typename T>
T* RawPointer(T* p) { return p; }
template <typename Smart>
auto* RawPointer(const Smart& p) { return p.get(); }

// Host code between kernel calls that uses a std::vector member (after crt_Synchronize, the GPU idle):
// its device copy read back whole, and uploaded whole after the host changed it. The vector keeps
// the size its buffer was made for while the call runs (resizing there is refused).
template <typename Vector>
void DownloadVector(const Buffer& buffer, Vector& vector) {
  if (!vector.empty()) buffer.Download(vector.data(), sizeof(vector[0]) * vector.size());
}
template <typename Vector>
void UploadVector(Buffer& buffer, const Vector& vector) {
  if (!vector.empty()) buffer.Upload(vector.data(), sizeof(vector[0]) * vector.size());
}

// After kernels appended to a std::vector member on the GPU: reads the count they reached (the
// uint32_t at sizeOffset of `counts`), gives the host vector that size and the elements. The size
// stays within the capacity, so the vector is not reallocated. Pushes past the capacity were
// counted but not stored: that throws, after the stored elements are read.
template <typename Vector>
void ReadAppended(const Buffer& counts, size_t sizeOffset, const Buffer& elements, Vector& vector, const char* name) {
  uint32_t appended = 0;
  counts.Download(&appended, sizeof(appended), sizeOffset);
  const size_t stored = appended < vector.capacity() ? appended : vector.capacity();
  vector.resize(stored);
  if (stored > 0) elements.Download(vector.data(), sizeof(vector[0]) * stored);
  if (appended > stored)
    throw Error(std::string(name) + ": kernels appended " + std::to_string(appended) + " elements, but its capacity is " +
                std::to_string(vector.capacity()) + "; the GPU keeps only that many. Call reserve(" +
                std::to_string(appended) + ") or more before the call (the first " + std::to_string(stored) + " were kept)");
}

// Reallocates b (keeping its extra usage) only when it is empty or smaller than bytes.
void EnsureSize(std::shared_ptr<VulkanContext> ctx, Buffer& b, VkDeviceSize bytes);
// EnsureSize for scratch that commands already recorded may use: a replaced buffer moves to
// `retired` instead of being destroyed.
void GrowScratch(std::shared_ptr<VulkanContext> ctx, Buffer& b, VkDeviceSize bytes, std::vector<Buffer>& retired);

// ---- arrays of textures: std::vector<LiteImage::Texture2D<T>> members --------------------------
// Kernels sample them by a per-thread index. Two ways, chosen at run time:
// - TextureArray: an image and a sampler per texture in a descriptor set, for devices with
//   descriptor indexing (VulkanContext::hasTextureArrays); the GPU's samplers filter.
// - TextureBuffers: every texel in one storage buffer and a TextureInfo per texture; the kernels'
//   own sampler (generated GLSL) filters as LiteImage::Image2D::sample does, on any device.

// One texture as the generated sampler reads it (std430, 32 bytes; GLSL struct crt_TextureInfo).
struct TextureInfo {
  uint32_t offset = 0;  // its first texel in the texel buffer
  uint32_t width = 0, height = 0;
  uint32_t mode = 0;    // addressU | addressV << 3 | linear << 6; address modes numbered as LiteImage's
  float border[4] = {0, 0, 0, 0};
};

// The TextureInfo of a LiteImage::Texture2D (any type with its members: the runtime does not depend on LiteImage).
template <typename Texture>
TextureInfo DescribeTexture(const Texture& t, uint32_t offset) {
  using Filter = typename std::decay_t<decltype(t.sampler())>::Filter;
  TextureInfo info;
  info.offset = offset;
  info.width = t.width();
  info.height = t.height();
  info.mode = uint32_t(t.sampler().addressU) | uint32_t(t.sampler().addressV) << 3 | uint32_t(t.sampler().filter == Filter::LINEAR) << 6;
  info.border[0] = t.sampler().borderColor.x;
  info.border[1] = t.sampler().borderColor.y;
  info.border[2] = t.sampler().borderColor.z;
  info.border[3] = t.sampler().borderColor.w;
  return info;
}

// Uploads the TextureInfos of `textures` to `infos` and, unless `texels` is null, their texels one
// after the other to *texels, for the generated sampler. Buffers grow as needed and hold at least
// one element.
template <typename Textures>
void CommitTextureBuffers(std::shared_ptr<VulkanContext> ctx, const Textures& textures, Buffer& infos, Buffer* texels) {
  using Texel = std::remove_const_t<std::remove_pointer_t<decltype(textures[0].image().data())>>;
  std::vector<TextureInfo> table(textures.size() == 0 ? 1 : textures.size());
  size_t total = 0;
  for (size_t i = 0; i < textures.size(); ++i) {
    const size_t texelCount = size_t(textures[i].width()) * textures[i].height();
    if (total + texelCount > UINT32_MAX) throw Error("CommitTextureBuffers: the textures hold more than 2^32 texels");
    table[i] = DescribeTexture(textures[i], uint32_t(total));
    total += texelCount;
  }
  EnsureSize(ctx, infos, sizeof(TextureInfo) * table.size());
  infos.Upload(table.data(), sizeof(TextureInfo) * table.size());
  if (!texels) return;
  EnsureSize(ctx, *texels, sizeof(Texel) * (total == 0 ? 1 : total));
  for (size_t i = 0; i < textures.size(); ++i)
    if (textures[i].width() > 0 && textures[i].height() > 0)
      texels->Upload(textures[i].image().data(), sizeof(Texel) * textures[i].width() * textures[i].height(), sizeof(Texel) * table[i].offset);
}

// The descriptor set of an array of combined image samplers: one GPU image per texture (1 x 1
// while empty) and one sampler per distinct LiteImage::Sampler. Move-only.
class TextureArray {
public:
  struct Texture {
    const void* texels = nullptr;  // tightly packed rows of the array's format
    uint32_t width = 0, height = 0;
    SamplerDesc sampler;
  };
  TextureArray() = default;
  // Throws unless ctx->hasTextureArrays.
  TextureArray(std::shared_ptr<VulkanContext> ctx, const char* debugName);
  TextureArray(TextureArray&& other) noexcept;
  TextureArray& operator=(TextureArray&& other) noexcept;
  TextureArray(const TextureArray&) = delete;
  TextureArray& operator=(const TextureArray&) = delete;
  ~TextureArray();

  // Replaces the textures (synchronous uploads) and rewrites the set. Throws for more textures
  // than maxTextureArraySize, and for linear filtering of a format the device cannot filter.
  void Assign(VkFormat format, const std::vector<Texture>& textures);
  VkDescriptorSet Set() const { return set_; }

private:
  void Release() noexcept;
  std::shared_ptr<VulkanContext> ctx_;
  std::string name_;
  std::vector<Image> images_;
  std::vector<Sampler> samplers_;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
};

// TextureArray::Assign from a vector of LiteImage::Texture2D.
template <typename Textures>
void AssignTextures(TextureArray& array, VkFormat format, const Textures& textures) {
  std::vector<TextureArray::Texture> list(textures.size());
  for (size_t i = 0; i < textures.size(); ++i)
    list[i] = {textures[i].image().data(), textures[i].width(), textures[i].height(), DescribeSampler(textures[i].sampler())};
  array.Assign(format, list);
}

// What compute and ray tracing pipelines share, move-only: the layout (set 0 a push-descriptor set,
// sets 1, 2, ... arrays of textures, push constants), binding resources and push constants.
class Pipeline {
public:
  void Bind(VkCommandBuffer cmd) const;
  // Binding i = i-th view, via vkCmdPushDescriptorSetKHR. The count must equal the binding count.
  void PushBuffers(VkCommandBuffer cmd, std::initializer_list<BufferView> buffers) const;
  // Binding i = i-th entry, whose type must be the layout's.
  void PushBindings(VkCommandBuffer cmd, std::initializer_list<Binding> bindings) const;
  void PushConstants(VkCommandBuffer cmd, const void* data, uint32_t bytes) const;
  // Binds the arrays as sets 1, 2, ...; their number must be the pipeline's textureArraySets.
  void BindTextureArrays(VkCommandBuffer cmd, std::initializer_list<const TextureArray*> arrays) const;
  VkPipeline Handle() const { return pipeline_; }
  VkPipelineLayout Layout() const { return layout_; }

protected:
  Pipeline() = default;
  // Checks the arguments and creates the layout, for shaders of `stages`; `kind` names the class in errors.
  Pipeline(const char* kind, VkPipelineBindPoint bindPoint, VkShaderStageFlags stages, std::shared_ptr<VulkanContext> ctx,
           std::vector<VkDescriptorType> bindingTypes, uint32_t pushConstantBytes, const char* debugName, uint32_t textureArraySets);
  Pipeline(Pipeline&& other) noexcept;
  Pipeline& operator=(Pipeline&& other) noexcept;
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;
  ~Pipeline();
  void Release() noexcept;
  std::string Where() const { return std::string(kind_) + " '" + name_ + "'"; }  // for errors
  VkShaderModule CreateModule(const uint32_t* spirv, size_t spirvBytes) const;  // throws on bad SPIR-V

  std::shared_ptr<VulkanContext> ctx_;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  std::string name_;

private:
  void Push(VkCommandBuffer cmd, const std::vector<Binding>& bindings) const;

  const char* kind_ = "Pipeline";
  VkPipelineBindPoint bindPoint_ = VK_PIPELINE_BIND_POINT_COMPUTE;
  VkShaderStageFlags stages_ = 0;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorType> types_;
  uint32_t textureArraySets_ = 0;
  uint32_t pushConstantBytes_ = 0;
};

// RAII compute pipeline, move-only.
class ComputePipeline : public Pipeline {
public:
  ComputePipeline() = default;
  // storageBufferBindings: bindings 0..n-1 in set 0; pushConstantBytes may be 0.
  ComputePipeline(std::shared_ptr<VulkanContext> ctx, const uint32_t* spirv, size_t spirvBytes,
                  uint32_t storageBufferBindings, uint32_t pushConstantBytes, const char* debugName,
                  const std::vector<uint32_t>& constants = {});
  // Binding i of set 0 has bindingTypes[i] (storage buffers, storage images, sampled images, samplers);
  // sets 1..textureArraySets are arrays of textures (throws unless ctx->hasTextureArrays).
  // constants: the values of the specialization constants kClassConstantIdBase + i (none given: the
  // shader's defaults).
  ComputePipeline(std::shared_ptr<VulkanContext> ctx, const uint32_t* spirv, size_t spirvBytes,
                  std::vector<VkDescriptorType> bindingTypes, uint32_t pushConstantBytes, const char* debugName,
                  uint32_t textureArraySets = 0, const std::vector<uint32_t>& constants = {});
};

// SPIR-V code of one shader: a pointer into the generated arrays, and its size in bytes.
struct ShaderCode {
  const uint32_t* spirv = nullptr;
  size_t bytes = 0;
};

// The shaders of a ray tracing pipeline. traceRayEXT(..., missIndex, ...) runs misses[missIndex];
// a leaf whose instance has shader binding table offset i runs hitGroups[i] (procedural geometry: its
// intersection shader, then the closest-hit shader for the nearest); executeCallableEXT(i, ...) runs
// callables[i].
struct RayTracingShaders {
  struct HitGroup {
    ShaderCode intersection, closestHit;
  };
  ShaderCode rayGeneration;
  std::vector<ShaderCode> misses;
  std::vector<HitGroup> hitGroups;
  std::vector<ShaderCode> callables;
};

// RAII ray tracing pipeline (virtual functions, level 3), move-only: a kernel as a ray generation
// shader, whose virtual calls run as callable shaders or whose traversal traces rays against leaves
// intersected by intersection shaders. Bindings and push constants are visible to every stage; sets
// 1..textureArraySets are arrays of textures, which the ray generation and callable shaders sample.
// Throws unless ctx->hasRayTracingPipeline (and ctx->hasTextureArrays, with texture sets).
class RayTracingPipeline : public Pipeline {
public:
  RayTracingPipeline() = default;
  // constants: as ComputePipeline's, for every stage.
  RayTracingPipeline(std::shared_ptr<VulkanContext> ctx, const RayTracingShaders& shaders, std::vector<VkDescriptorType> bindingTypes,
                     uint32_t pushConstantBytes, const char* debugName, uint32_t textureArraySets = 0,
                     const std::vector<uint32_t>& constants = {});
  // Launches width x height x depth ray generation threads (gl_LaunchIDEXT), behind and ahead of
  // barriers to and from the compute and transfer stages the other commands use.
  void TraceCmd(VkCommandBuffer cmd, uint32_t width, uint32_t height, uint32_t depth) const;

private:
  Buffer table_;  // the shader binding table: the ray generation record, then the misses', hit groups' and callables'
  VkStridedDeviceAddressRegionKHR rayGenRegion_{}, missRegion_{}, hitRegion_{}, callableRegion_{};
};

// Dispatch `threads` threads in groups of `groupSize` (1D). Above 65535 groups (the minimum
// maxComputeWorkGroupCount every device has) the groups are spread over y; shaders compute
//   id = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x
// and skip ids >= threads. Returns the number of groups launched (x*y).
uint32_t Dispatch1D(VkCommandBuffer cmd, uint64_t threads, uint32_t groupSize);
void Dispatch2D(VkCommandBuffer cmd, uint32_t threadsX, uint32_t threadsY, uint32_t groupX, uint32_t groupY);
void Dispatch3D(VkCommandBuffer cmd, uint32_t tx, uint32_t ty, uint32_t tz, uint32_t gx, uint32_t gy, uint32_t gz);
uint32_t GroupCount1D(uint64_t threads, uint32_t groupSize);  // total groups Dispatch1D would launch
// Shader writes -> later shader reads/writes and transfers (compute -> compute|transfer).
void ComputeBarrier(VkCommandBuffer cmd);
// Transfer writes (copy/fill) -> later shader reads/writes.
void TransferToComputeBarrier(VkCommandBuffer cmd);

// GPU timing with timestamp queries, for GetExecutionTime(). One per generated class.
class GpuTimer {
public:
  GpuTimer() = default;
  explicit GpuTimer(std::shared_ptr<VulkanContext> ctx, uint32_t maxQueries = 256);
  GpuTimer(GpuTimer&& other) noexcept;
  GpuTimer& operator=(GpuTimer&& other) noexcept;
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;
  ~GpuTimer();

  void Reset(VkCommandBuffer cmd);                            // vkCmdResetQueryPool
  void Begin(VkCommandBuffer cmd, const std::string& name);   // timestamp at TOP_OF_PIPE
  void End(VkCommandBuffer cmd, const std::string& name);     // timestamp at ALL_COMMANDS
  // After the submission completed: read results; the sum of this submission's intervals per name
  // becomes that name's last duration.
  void Collect();
  float LastMs(const std::string& name) const;  // 0 if unknown

private:
  struct Interval {
    std::string name;
    uint32_t begin;
    uint32_t end;  // UINT32_MAX while open
  };
  void Release() noexcept;

  std::shared_ptr<VulkanContext> ctx_;
  VkQueryPool pool_ = VK_NULL_HANDLE;  // null when timestamps are unsupported: everything reports 0
  uint32_t maxQueries_ = 0;
  uint32_t used_ = 0;
  uint64_t validMask_ = 0;
  std::vector<Interval> intervals_;
  std::unordered_map<std::string, float> lastMs_;
};

// steady_clock stopwatch; starts on construction.
struct CpuTimer {
  CpuTimer() { start(); }
  void start() { t0 = std::chrono::steady_clock::now(); }
  float ElapsedMs() const {
    return std::chrono::duration<float, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  std::chrono::steady_clock::time_point t0;
};

// ---- primitives the translator maps library calls of control functions to ------------------

// The 32-bit pattern of a value, for push constants and buffer fills.
template <typename T>
uint32_t Bits32(T value) {
  static_assert(sizeof(T) == 4, "32-bit element types only");
  uint32_t bits;
  std::memcpy(&bits, &value, 4);
  return bits;
}

// std::exclusive_scan / std::inclusive_scan on the GPU: blocks of 1024 elements scanned with
// subgroup arithmetic, block totals scanned recursively, offsets added. Any n, no padding.
class Scanner {
public:
  Scanner() = default;
  explicit Scanner(std::shared_ptr<VulkanContext> ctx);
  // out[i] = init + in[0] + ... + in[i-1] (exclusive) or ... + in[i] (inclusive), i < n.
  // `in` may be `out`. Ends with a barrier. Scratch buffers grow as needed and are kept; the
  // ones they replace stay alive, since commands recorded earlier may still use them, until
  // ReleaseRetired().
  void RecordCmd(VkCommandBuffer cmd, BufferView in, BufferView out, uint32_t n, bool inclusive, ElementType type,
                 uint32_t initBits = 0);
  // Frees replaced scratch: call when every command buffer recorded so far has completed.
  void ReleaseRetired() { retired_.clear(); }

private:
  struct Level { Buffer sums; };
  void Init();
  std::shared_ptr<VulkanContext> ctx_;
  ComputePipeline blocks_[3], add_[3];
  std::vector<Level> levels_;
  std::vector<Buffer> retired_;
};

// std::sort on the GPU: a stable LSD radix sort, 4 passes of 8 bits (tile histograms, an
// exclusive scan of them, a stable scatter of whole records). Any n, no padding to a power of
// two. Records with equal keys keep their order (std::sort leaves it unspecified).
class RadixSorter {
public:
  RadixSorter() = default;
  explicit RadixSorter(std::shared_ptr<VulkanContext> ctx);
  // Sorts records[0..n) in place. Ends with a barrier. Scratch grows as needed (see
  // Scanner::RecordCmd).
  void RecordCmd(VkCommandBuffer cmd, BufferView records, uint32_t n, SortKey key = {});
  // Sorts records[0..min(n, count)) where count is the uint `countOffset` bytes into `counts`,
  // known only on the GPU (the size of a vector that kernels appended to; n is its capacity).
  // The work is that of sorting n records.
  void RecordCmd(VkCommandBuffer cmd, BufferView records, uint32_t n, SortKey key, BufferView counts, uint32_t countOffset);
  // See Scanner::ReleaseRetired.
  void ReleaseRetired() {
    retired_.clear();
    scanner_.ReleaseRetired();
  }

private:
  std::shared_ptr<VulkanContext> ctx_;
  ComputePipeline histogram_, scatter_;
  Scanner scanner_;
  Buffer recordsTmp_, counts_;
  std::vector<Buffer> retired_;
};

// Dispatch of a 1D kernel whose thread count lives on the GPU: the size of a std::vector member
// that earlier kernels appended to (push_back), capped at its capacity. One thread turns the count
// into group counts, vkCmdDispatchIndirect launches them: no host round trip. The groups are
// spread over y as Dispatch1D spreads them; the kernel tests its ids against the count itself.
class IndirectDispatcher {
public:
  IndirectDispatcher() = default;
  // One slot of group counts per kernel dispatched indirectly.
  IndirectDispatcher(std::shared_ptr<VulkanContext> ctx, uint32_t slots);
  // Records the computation of slot's groups: threads = min(the uint at sizeOffset, the uint at
  // capacityOffset) of `counts`. Binds its own pipeline: bind the kernel's afterwards.
  void PrepareCmd(VkCommandBuffer cmd, uint32_t slot, BufferView counts, uint32_t sizeOffset, uint32_t capacityOffset,
                  uint32_t groupSize);
  // Launches the bound pipeline with slot's groups.
  void DispatchCmd(VkCommandBuffer cmd, uint32_t slot) const;

private:
  std::shared_ptr<VulkanContext> ctx_;
  ComputePipeline groups_;
  Buffer args_;  // one VkDispatchIndirectCommand per slot, stride_ bytes apart
  VkDeviceSize stride_ = 0;
  uint32_t slots_ = 0;
};

// A view `bytes` further into a buffer view.
inline BufferView Offset(BufferView v, VkDeviceSize bytes) {
  return {v.buffer, v.offset + bytes, v.range == VK_WHOLE_SIZE ? VK_WHOLE_SIZE : v.range - bytes};
}

// memcpy between device buffers, with the barriers around it.
void CopyCmd(VkCommandBuffer cmd, BufferView src, BufferView dst, VkDeviceSize bytes);
// std::fill of 32-bit elements: fills `bytes` bytes with the pattern.
void FillCmd(VkCommandBuffer cmd, BufferView dst, VkDeviceSize bytes, uint32_t bits);
// Zeroes the first `bytes` of a buffer in order with the commands around it (the device copy of a
// vector that kernels then add into); throws when the buffer is smaller, naming `what`.
void ZeroCmd(VkCommandBuffer cmd, const Buffer& buffer, VkDeviceSize bytes, const char* what);

}  // namespace crossrt
