// VulkanContext: instance, device selection, device, command pool, validation messages and the
// on-disk pipeline cache.
#include "crossrt/VulkanRuntime.h"
#include "Internal.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace crossrt {

const char* ResultName(VkResult r) {
  switch (r) {
#define CROSSRT_RESULT(x) \
  case x:                 \
    return #x;
    CROSSRT_RESULT(VK_SUCCESS)
    CROSSRT_RESULT(VK_NOT_READY)
    CROSSRT_RESULT(VK_TIMEOUT)
    CROSSRT_RESULT(VK_EVENT_SET)
    CROSSRT_RESULT(VK_EVENT_RESET)
    CROSSRT_RESULT(VK_INCOMPLETE)
    CROSSRT_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
    CROSSRT_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    CROSSRT_RESULT(VK_ERROR_INITIALIZATION_FAILED)
    CROSSRT_RESULT(VK_ERROR_DEVICE_LOST)
    CROSSRT_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
    CROSSRT_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
    CROSSRT_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
    CROSSRT_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
    CROSSRT_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
    CROSSRT_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
    CROSSRT_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
    CROSSRT_RESULT(VK_ERROR_FRAGMENTED_POOL)
    CROSSRT_RESULT(VK_ERROR_UNKNOWN)
    CROSSRT_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
    CROSSRT_RESULT(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    CROSSRT_RESULT(VK_ERROR_FRAGMENTATION)
    CROSSRT_RESULT(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
    CROSSRT_RESULT(VK_PIPELINE_COMPILE_REQUIRED)
    CROSSRT_RESULT(VK_ERROR_SURFACE_LOST_KHR)
    CROSSRT_RESULT(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
    CROSSRT_RESULT(VK_SUBOPTIMAL_KHR)
    CROSSRT_RESULT(VK_ERROR_OUT_OF_DATE_KHR)
    CROSSRT_RESULT(VK_ERROR_VALIDATION_FAILED_EXT)
    CROSSRT_RESULT(VK_THREAD_IDLE_KHR)
    CROSSRT_RESULT(VK_THREAD_DONE_KHR)
    CROSSRT_RESULT(VK_OPERATION_DEFERRED_KHR)
    CROSSRT_RESULT(VK_OPERATION_NOT_DEFERRED_KHR)
#undef CROSSRT_RESULT
    default:
      return "VK_RESULT_UNKNOWN";
  }
}

void Check(VkResult r, const char* what) {
  if (r == VK_SUCCESS) return;
  throw Error(std::string(what) + " failed: " + ResultName(r) + " (" + std::to_string(static_cast<int>(r)) + ")");
}

namespace {

const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
const char* kNoDeviceMessage =
    "no Vulkan device found: install a Vulkan driver (e.g. mesa-vulkan-drivers for the lavapipe CPU driver) "
    "or check VK_ICD_FILENAMES / VK_DRIVER_FILES";

std::string ToLower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool HasExtension(const std::vector<VkExtensionProperties>& exts, const char* name) {
  for (const auto& e : exts)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

std::vector<VkExtensionProperties> InstanceExtensions(const char* layer) {
  uint32_t n = 0;
  if (vkEnumerateInstanceExtensionProperties(layer, &n, nullptr) != VK_SUCCESS) return {};
  std::vector<VkExtensionProperties> exts(n);
  if (vkEnumerateInstanceExtensionProperties(layer, &n, exts.data()) < 0) return {};
  exts.resize(n);
  return exts;
}

std::vector<VkExtensionProperties> DeviceExtensions(VkPhysicalDevice pd) {
  uint32_t n = 0;
  Check(vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr), "vkEnumerateDeviceExtensionProperties");
  std::vector<VkExtensionProperties> exts(n);
  VkResult r = vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, exts.data());
  if (r < 0) Check(r, "vkEnumerateDeviceExtensionProperties");
  exts.resize(n);
  return exts;
}

std::vector<VkQueueFamilyProperties> QueueFamilies(VkPhysicalDevice pd) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, families.data());
  families.resize(n);
  return families;
}

// First family with COMPUTE, preferring one that can write timestamps (GpuTimer needs them).
int ComputeFamily(VkPhysicalDevice pd) {
  auto families = QueueFamilies(pd);
  int fallback = -1;
  for (uint32_t i = 0; i < families.size(); ++i) {
    if (!(families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) || families[i].queueCount == 0) continue;
    if (families[i].timestampValidBits > 0) return static_cast<int>(i);
    if (fallback < 0) fallback = static_cast<int>(i);
  }
  return fallback;
}

const char* TypeName(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU";
    default: return "other";
  }
}

int TypeScore(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 1;
    default: return 0;
  }
}

struct Candidate {
  VkPhysicalDevice pd;
  VkPhysicalDeviceProperties props;
  std::string problem;  // empty when usable
};

std::string Hex(const uint8_t* data, size_t n) {
  static const char* digits = "0123456789abcdef";
  std::string s;
  for (size_t i = 0; i < n; ++i) {
    s += digits[data[i] >> 4];
    s += digits[data[i] & 15];
  }
  return s;
}

bool EnvFlag(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::strcmp(v, "0") != 0 && ToLower(v) != "false" && ToLower(v) != "off";
}

}  // namespace

std::shared_ptr<VulkanContext> VulkanContext::CreateDefault() {
  ContextOptions options;
  if (const char* d = std::getenv("CROSSRT_DEVICE")) options.device = d;
  options.validation = EnvFlag("CROSSRT_VALIDATION");
  return Create(options);
}

std::shared_ptr<VulkanContext> VulkanContext::Create(const ContextOptions& options) {
  // Own the object before Init so a throw mid-way still destroys what was created.
  std::shared_ptr<VulkanContext> ctx(new VulkanContext());
  ctx->Init(options);
  return ctx;
}

void VulkanContext::Init(const ContextOptions& options) {
  forceStaging = options.forceStaging;
  stagingCache = MakeStagingCache();
  CreateInstance(options);
  CreateDevice(options);

  auto poolInfo = VkInit<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  poolInfo.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT | VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  poolInfo.queueFamilyIndex = queueFamily;
  Check(vkCreateCommandPool(device, &poolInfo, nullptr, &commandPool), "vkCreateCommandPool");

  LoadPipelineCache();
}

void VulkanContext::CreateInstance(const ContextOptions& options) {
  uint32_t loaderVersion = VK_API_VERSION_1_0;
  if (vkEnumerateInstanceVersion(&loaderVersion) != VK_SUCCESS) loaderVersion = VK_API_VERSION_1_0;

  std::vector<const char*> layers, extensions;
  bool debugUtils = false;
  if (options.validation) {
    uint32_t n = 0;
    vkEnumerateInstanceLayerProperties(&n, nullptr);
    std::vector<VkLayerProperties> available(n);
    vkEnumerateInstanceLayerProperties(&n, available.data());
    available.resize(n);
    bool found = std::any_of(available.begin(), available.end(),
                             [](const VkLayerProperties& l) { return std::strcmp(l.layerName, kValidationLayer) == 0; });
    if (!found)
      throw Error(std::string("Vulkan validation was requested (CROSSRT_VALIDATION=1) but ") + kValidationLayer +
                  " is not installed: install the vulkan-validationlayers package (or the Vulkan SDK), "
                  "or turn validation off");
    layers.push_back(kValidationLayer);
    debugUtils = HasExtension(InstanceExtensions(nullptr), VK_EXT_DEBUG_UTILS_EXTENSION_NAME) ||
                 HasExtension(InstanceExtensions(kValidationLayer), VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    if (debugUtils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }

  auto app = VkInit<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  app.pApplicationName = "CrossRT";
  app.pEngineName = "CrossRT";
  // 1.3 when the loader has it, else 1.2 (the features we use are 1.2 core).
  app.apiVersion = loaderVersion >= VK_API_VERSION_1_3 ? VK_API_VERSION_1_3 : VK_API_VERSION_1_2;

  // Only WARNING/ERROR: INFO/VERBOSE is mostly loader chatter.
  auto messengerInfo = VkInit<VkDebugUtilsMessengerCreateInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
  messengerInfo.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messengerInfo.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messengerInfo.pfnUserCallback = &VulkanContext::DebugCallback;
  messengerInfo.pUserData = this;

  auto info = VkInit<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  // Chained messenger also reports problems inside vkCreateInstance/vkDestroyInstance.
  if (debugUtils) info.pNext = &messengerInfo;

  VkResult r = vkCreateInstance(&info, nullptr, &instance);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER) {
    instance = VK_NULL_HANDLE;
    throw NoDeviceError(kNoDeviceMessage);
  }
  Check(r, "vkCreateInstance");

  if (debugUtils) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    if (create) Check(create(instance, &messengerInfo, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
    setObjectName_ = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
        vkGetInstanceProcAddr(instance, "vkSetDebugUtilsObjectNameEXT"));
  }
}

void VulkanContext::CreateDevice(const ContextOptions& options) {
  uint32_t count = 0;
  VkResult r = vkEnumeratePhysicalDevices(instance, &count, nullptr);
  // Some loaders report a missing driver here rather than at vkCreateInstance.
  if (r == VK_ERROR_INITIALIZATION_FAILED || r == VK_ERROR_INCOMPATIBLE_DRIVER || (r == VK_SUCCESS && count == 0))
    throw NoDeviceError(kNoDeviceMessage);
  Check(r, "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> devices(count);
  r = vkEnumeratePhysicalDevices(instance, &count, devices.data());
  if (r < 0) Check(r, "vkEnumeratePhysicalDevices");
  devices.resize(count);
  if (devices.empty()) throw NoDeviceError(kNoDeviceMessage);

  std::vector<Candidate> candidates;
  std::ostringstream list;
  for (uint32_t i = 0; i < devices.size(); ++i) {
    Candidate c{devices[i], {}, {}};
    vkGetPhysicalDeviceProperties(c.pd, &c.props);
    if (VK_API_VERSION_MINOR(c.props.apiVersion) < 1 && VK_API_VERSION_MAJOR(c.props.apiVersion) == 1)
      c.problem = "Vulkan 1.0 only";
    else if (!HasExtension(DeviceExtensions(c.pd), VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME))
      c.problem = "no VK_KHR_push_descriptor";
    else if (ComputeFamily(c.pd) < 0)
      c.problem = "no compute queue";
    list << "\n  [" << i << "] " << c.props.deviceName << " (" << TypeName(c.props.deviceType) << ")";
    if (!c.problem.empty()) list << " - unusable: " << c.problem;
    candidates.push_back(c);
  }

  int chosen = -1;
  if (!options.device.empty()) {
    const std::string& want = options.device;
    if (std::all_of(want.begin(), want.end(), [](unsigned char ch) { return std::isdigit(ch) != 0; })) {
      unsigned long idx = std::strtoul(want.c_str(), nullptr, 10);
      if (idx < candidates.size()) chosen = static_cast<int>(idx);
    } else {
      for (size_t i = 0; i < candidates.size() && chosen < 0; ++i)
        if (ToLower(candidates[i].props.deviceName).find(ToLower(want)) != std::string::npos)
          chosen = static_cast<int>(i);
    }
    if (chosen < 0)
      throw Error("Vulkan device '" + want + "' (CROSSRT_DEVICE) not found; available devices:" + list.str());
    if (!candidates[chosen].problem.empty())
      throw Error(std::string("Vulkan device '") + candidates[chosen].props.deviceName +
                  "' cannot be used by CrossRT: " + candidates[chosen].problem + "; available devices:" + list.str());
  } else {
    int bestScore = -1;
    for (size_t i = 0; i < candidates.size(); ++i) {
      if (!candidates[i].problem.empty()) continue;
      int score = TypeScore(candidates[i].props.deviceType);
      if (score > bestScore) {
        bestScore = score;
        chosen = static_cast<int>(i);
      }
    }
    if (chosen < 0)
      throw Error("no usable Vulkan device (CrossRT needs Vulkan 1.1+, VK_KHR_push_descriptor and a compute queue); "
                  "available devices:" + list.str());
  }

  physicalDevice = candidates[chosen].pd;
  properties = candidates[chosen].props;
  queueFamily = static_cast<uint32_t>(ComputeFamily(physicalDevice));
  vkGetPhysicalDeviceMemoryProperties(physicalDevice, &memoryProperties_);

  // Extensions: push descriptors (required) + the optional ones that exist. Ray query needs
  // acceleration structures, which need deferred host operations: drop a dependent whose base is missing.
  const char* envFeatures = std::getenv("CROSSRT_DEVICE_FEATURES");
  const DeviceFeatureMask mask = ParseDeviceFeatures(options.deviceFeatures + "," + (envFeatures ? envFeatures : ""));
  auto hiddenExtension = [&](const char* name) {
    return (mask.Hidden(DeviceFeature::RayQuery) && std::strcmp(name, VK_KHR_RAY_QUERY_EXTENSION_NAME) == 0) ||
           (mask.Hidden(DeviceFeature::RayTracingPipeline) && std::strcmp(name, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME) == 0) ||
           (mask.Hidden(DeviceFeature::FloatAtomics) && std::strcmp(name, VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME) == 0);
  };
  auto available = DeviceExtensions(physicalDevice);
  std::vector<const char*> extensions{VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
  auto wanted = [&](const char* name) {
    return !hiddenExtension(name) && HasExtension(available, name) &&
           std::any_of(options.optionalDeviceExtensions.begin(), options.optionalDeviceExtensions.end(),
                       [&](const char* e) { return e && std::strcmp(e, name) == 0; });
  };
  bool deferredOps = wanted(VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME);
  bool accel = deferredOps && wanted(VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME);
  bool rayQuery = accel && wanted(VK_KHR_RAY_QUERY_EXTENSION_NAME);
  bool rayPipeline = accel && wanted(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
  for (const char* e : options.optionalDeviceExtensions) {
    if (!e || !HasExtension(available, e) || hiddenExtension(e) || std::strcmp(e, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME) == 0) continue;
    if (std::strcmp(e, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME) == 0 && !accel) continue;
    if (std::strcmp(e, VK_KHR_RAY_QUERY_EXTENSION_NAME) == 0 && !rayQuery) continue;
    if (std::strcmp(e, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME) == 0 && !rayPipeline) continue;
    bool dup = std::any_of(extensions.begin(), extensions.end(), [&](const char* x) { return std::strcmp(x, e) == 0; });
    if (!dup) extensions.push_back(e);
  }

  // Query what is supported, then enable only the features we use.
  bool vk12 = VK_API_VERSION_MINOR(properties.apiVersion) >= 2 || VK_API_VERSION_MAJOR(properties.apiVersion) > 1;
  auto supported12 = VkInit<VkPhysicalDeviceVulkan12Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
  auto supportedAs = VkInit<VkPhysicalDeviceAccelerationStructureFeaturesKHR>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR);
  auto supportedRq = VkInit<VkPhysicalDeviceRayQueryFeaturesKHR>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR);
  auto supportedRt = VkInit<VkPhysicalDeviceRayTracingPipelineFeaturesKHR>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR);
  auto supportedAf = VkInit<VkPhysicalDeviceShaderAtomicFloatFeaturesEXT>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT);
  auto supported = VkInit<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2);
  const bool atomicFloat = std::any_of(extensions.begin(), extensions.end(), [](const char* e) { return std::strcmp(e, VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME) == 0; });
  void** tail = &supported.pNext;
  if (atomicFloat) { *tail = &supportedAf; tail = &supportedAf.pNext; }
  if (vk12) { *tail = &supported12; tail = &supported12.pNext; }
  if (rayQuery || rayPipeline) { *tail = &supportedAs; tail = &supportedAs.pNext; }
  if (rayQuery) { *tail = &supportedRq; tail = &supportedRq.pNext; }
  if (rayPipeline) { *tail = &supportedRt; tail = &supportedRt.pNext; }
  vkGetPhysicalDeviceFeatures2(physicalDevice, &supported);

  auto enable12 = VkInit<VkPhysicalDeviceVulkan12Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
  auto enableAs = VkInit<VkPhysicalDeviceAccelerationStructureFeaturesKHR>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR);
  auto enableRq = VkInit<VkPhysicalDeviceRayQueryFeaturesKHR>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR);
  auto enableRt = VkInit<VkPhysicalDeviceRayTracingPipelineFeaturesKHR>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR);
  auto enableAf = VkInit<VkPhysicalDeviceShaderAtomicFloatFeaturesEXT>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT);
  auto enable = VkInit<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2);
  enable.features.shaderInt64 = supported.features.shaderInt64;
  enable.features.shaderFloat64 = supported.features.shaderFloat64;
  tail = &enable.pNext;
  if (vk12) {
    enable12.scalarBlockLayout = supported12.scalarBlockLayout;
    enable12.bufferDeviceAddress = supported12.bufferDeviceAddress;
    enable12.samplerMirrorClampToEdge = supported12.samplerMirrorClampToEdge;
    // Arrays of textures indexed per thread (TextureArray): all four or none.
    if (!mask.Hidden(DeviceFeature::TextureArrays) &&
        supported12.runtimeDescriptorArray && supported12.shaderSampledImageArrayNonUniformIndexing &&
        supported12.descriptorBindingPartiallyBound && supported12.descriptorBindingVariableDescriptorCount) {
      enable12.runtimeDescriptorArray = enable12.shaderSampledImageArrayNonUniformIndexing = VK_TRUE;
      enable12.descriptorBindingPartiallyBound = enable12.descriptorBindingVariableDescriptorCount = VK_TRUE;
    }
    *tail = &enable12; tail = &enable12.pNext;
  }
  // Acceleration structures come with either; the pipeline's shader binding table needs device addresses.
  const bool accelOk = supportedAs.accelerationStructure && enable12.bufferDeviceAddress;
  if (accelOk && ((rayQuery && supportedRq.rayQuery) || (rayPipeline && supportedRt.rayTracingPipeline))) {
    enableAs.accelerationStructure = VK_TRUE;
    *tail = &enableAs; tail = &enableAs.pNext;
  }
  if (accelOk && rayQuery && supportedRq.rayQuery) {
    enableRq.rayQuery = VK_TRUE;
    *tail = &enableRq; tail = &enableRq.pNext;
  }
  if (accelOk && rayPipeline && supportedRt.rayTracingPipeline) {
    enableRt.rayTracingPipeline = VK_TRUE;
    *tail = &enableRt; tail = &enableRt.pNext;
  }
  if (atomicFloat && supportedAf.shaderBufferFloat32AtomicAdd) {
    enableAf.shaderBufferFloat32AtomicAdd = VK_TRUE;
    *tail = &enableAf; tail = &enableAf.pNext;
  }

  // Features CROSSRT_DEVICE_FEATURES requires: refused before the device exists.
  const bool offered[size_t(DeviceFeature::Count)] = {
      enableRq.rayQuery == VK_TRUE, enableRt.rayTracingPipeline == VK_TRUE, enable12.runtimeDescriptorArray == VK_TRUE,
      enableAf.shaderBufferFloat32AtomicAdd == VK_TRUE};
  for (size_t f = 0; f < size_t(DeviceFeature::Count); ++f)
    if (mask.required[f] && !offered[f])
      throw Error(std::string("CROSSRT_DEVICE_FEATURES requires ") + DeviceFeatureName(DeviceFeature(f)) +
                  ", which the Vulkan device '" + properties.deviceName + "' (" +
                  std::to_string(VK_API_VERSION_MAJOR(properties.apiVersion)) + "." +
                  std::to_string(VK_API_VERSION_MINOR(properties.apiVersion)) +
                  ") does not offer; scripts/install-lavapipe-rt.sh installs a lavapipe that has it");

  float priority = 1.0f;
  auto queueInfo = VkInit<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
  queueInfo.queueFamilyIndex = queueFamily;
  queueInfo.queueCount = 1;
  queueInfo.pQueuePriorities = &priority;

  auto info = VkInit<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
  info.pNext = &enable;  // features go through VkPhysicalDeviceFeatures2, so pEnabledFeatures stays null
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queueInfo;
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  Check(vkCreateDevice(physicalDevice, &info, nullptr, &device), "vkCreateDevice");
  vkGetDeviceQueue(device, queueFamily, 0, &queue);

  hasShaderInt64 = enable.features.shaderInt64 == VK_TRUE;

  VkPhysicalDeviceSubgroupProperties subgroup{};
  subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
  VkPhysicalDeviceProperties2 props2{};
  props2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
  props2.pNext = &subgroup;
  auto driver = VkInit<VkPhysicalDeviceDriverProperties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES);
  if (vk12) subgroup.pNext = &driver;
  vkGetPhysicalDeviceProperties2(physicalDevice, &props2);
  fenceAtomics = !(vk12 && driver.driverID == VK_DRIVER_ID_MESA_LLVMPIPE);
  loopIterationLimit = vk12 && driver.driverID == VK_DRIVER_ID_MESA_LLVMPIPE ? 65535u : 0u;
  subgroupSize = subgroup.subgroupSize;
  hasSubgroupArithmetic = (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
                          (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT);
  hasShaderFloat64 = enable.features.shaderFloat64 == VK_TRUE;
  hasScalarBlockLayout = enable12.scalarBlockLayout == VK_TRUE;
  hasBufferDeviceAddress = enable12.bufferDeviceAddress == VK_TRUE;
  hasMirrorClampToEdge = enable12.samplerMirrorClampToEdge == VK_TRUE;
  hasRayQuery = enableRq.rayQuery == VK_TRUE;
  hasFloatAtomicAdd = enableAf.shaderBufferFloat32AtomicAdd == VK_TRUE;
  hasRayTracingPipeline = enableRt.rayTracingPipeline == VK_TRUE;
  if (enable12.runtimeDescriptorArray) {
    // A kernel may sample a few arrays besides its own images: each array gets a quarter of what
    // one stage may bind, and at most 65536 textures.
    const VkPhysicalDeviceLimits& l = properties.limits;
    const uint32_t stageLimit = std::min({l.maxPerStageDescriptorSamplers, l.maxPerStageDescriptorSampledImages,
                                          l.maxDescriptorSetSamplers, l.maxDescriptorSetSampledImages});
    maxTextureArraySize = std::min<uint32_t>(65536, stageLimit > 64 ? (stageLimit - 32) / 4 : 0);
    if (maxTextureArraySize > 0) {
      const VkDescriptorBindingFlags flags = VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT | VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT;
      auto bindingFlags = VkInit<VkDescriptorSetLayoutBindingFlagsCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO);
      bindingFlags.bindingCount = 1;
      bindingFlags.pBindingFlags = &flags;
      // Compute shaders sample them, and where ray tracing pipelines exist, their ray generation
      // and callable shaders too (a kernel's level-3 variant).
      VkShaderStageFlags stages = VK_SHADER_STAGE_COMPUTE_BIT;
      if (hasRayTracingPipeline) stages |= VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_CALLABLE_BIT_KHR;
      const VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, maxTextureArraySize, stages, nullptr};
      auto setInfo = VkInit<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
      setInfo.pNext = &bindingFlags;
      setInfo.bindingCount = 1;
      setInfo.pBindings = &binding;
      Check(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &textureArrayLayout), "vkCreateDescriptorSetLayout (arrays of textures)");
      hasTextureArrays = true;
    }
  }

  // Which paths generated classes will take, once per process: asked for, or where the features are
  // chosen (the hw and sw variants of the tests print them).
  if (EnvFlag("CROSSRT_VERBOSE") || (envFeatures && *envFeatures)) {
    static std::once_flag once;
    std::call_once(once, [&] {
      std::fprintf(stderr,
                   "crossrt: Vulkan device '%s': ray queries %s, ray tracing pipelines %s, arrays of textures %s, "
                   "float atomics %s, subgroup size %u\n",
                   properties.deviceName, hasRayQuery ? "yes" : "no", hasRayTracingPipeline ? "yes" : "no",
                   hasTextureArrays ? "yes" : "no", hasFloatAtomicAdd ? "yes" : "no", subgroupSize);
    });
  }

  vkCmdPushDescriptorSetKHR = reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(
      vkGetDeviceProcAddr(device, "vkCmdPushDescriptorSetKHR"));
  if (!vkCmdPushDescriptorSetKHR) throw Error("vkCmdPushDescriptorSetKHR is missing although VK_KHR_push_descriptor is enabled");
  // Entry points of enabled extensions, which the loader does not export.
  auto load = [&](const char* name, const char* extension) {
    PFN_vkVoidFunction f = vkGetDeviceProcAddr(device, name);
    if (!f) throw Error(std::string(name) + " is missing although " + extension + " is enabled");
    return f;
  };
  if (hasRayQuery || hasRayTracingPipeline) {  // either comes with acceleration structures
    const char* as = VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME;
    vkGetAccelerationStructureBuildSizesKHR =
        reinterpret_cast<PFN_vkGetAccelerationStructureBuildSizesKHR>(load("vkGetAccelerationStructureBuildSizesKHR", as));
    vkCreateAccelerationStructureKHR = reinterpret_cast<PFN_vkCreateAccelerationStructureKHR>(load("vkCreateAccelerationStructureKHR", as));
    vkDestroyAccelerationStructureKHR = reinterpret_cast<PFN_vkDestroyAccelerationStructureKHR>(load("vkDestroyAccelerationStructureKHR", as));
    vkCmdBuildAccelerationStructuresKHR = reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresKHR>(load("vkCmdBuildAccelerationStructuresKHR", as));
    vkGetAccelerationStructureDeviceAddressKHR =
        reinterpret_cast<PFN_vkGetAccelerationStructureDeviceAddressKHR>(load("vkGetAccelerationStructureDeviceAddressKHR", as));
    auto accelLimits = VkInit<VkPhysicalDeviceAccelerationStructurePropertiesKHR>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR);
    auto accelProps = VkInit<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
    accelProps.pNext = &accelLimits;
    vkGetPhysicalDeviceProperties2(physicalDevice, &accelProps);
    accelerationScratchAlignment = std::max<VkDeviceSize>(1, accelLimits.minAccelerationStructureScratchOffsetAlignment);
  }
  if (hasRayTracingPipeline) {
    const char* rt = VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME;
    vkCreateRayTracingPipelinesKHR = reinterpret_cast<PFN_vkCreateRayTracingPipelinesKHR>(load("vkCreateRayTracingPipelinesKHR", rt));
    vkGetRayTracingShaderGroupHandlesKHR =
        reinterpret_cast<PFN_vkGetRayTracingShaderGroupHandlesKHR>(load("vkGetRayTracingShaderGroupHandlesKHR", rt));
    vkCmdTraceRaysKHR = reinterpret_cast<PFN_vkCmdTraceRaysKHR>(load("vkCmdTraceRaysKHR", rt));
    auto pipelineLimits = VkInit<VkPhysicalDeviceRayTracingPipelinePropertiesKHR>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR);
    auto pipelineProps = VkInit<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
    pipelineProps.pNext = &pipelineLimits;
    vkGetPhysicalDeviceProperties2(physicalDevice, &pipelineProps);
    shaderGroupHandleSize = pipelineLimits.shaderGroupHandleSize;
    shaderGroupHandleAlignment = std::max(1u, pipelineLimits.shaderGroupHandleAlignment);
    shaderGroupBaseAlignment = std::max(1u, pipelineLimits.shaderGroupBaseAlignment);
  }
}

VulkanContext::~VulkanContext() {
  if (device) {
    vkDeviceWaitIdle(device);
    stagingCache.reset();  // its buffers, before the device goes
    SavePipelineCache();
    if (pipelineCache) vkDestroyPipelineCache(device, pipelineCache, nullptr);
    if (commandPool) vkDestroyCommandPool(device, commandPool, nullptr);
    if (textureArrayLayout) vkDestroyDescriptorSetLayout(device, textureArrayLayout, nullptr);
    vkDestroyDevice(device, nullptr);
  }
  if (instance) {
    if (messenger_) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      if (destroy) destroy(instance, messenger_, nullptr);
    }
    vkDestroyInstance(instance, nullptr);
  }
}

std::string VulkanContext::DeviceName() const { return properties.deviceName; }

VKAPI_ATTR VkBool32 VKAPI_CALL VulkanContext::DebugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                            VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                                            const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                            void* user) {
  if (severity < VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT || !data || !user) return VK_FALSE;
  std::string msg = std::string(data->pMessageIdName ? data->pMessageIdName : "(no id)") + ": " +
                    (data->pMessage ? data->pMessage : "");
  std::fprintf(stderr, "[vulkan validation] %s\n", msg.c_str());
  auto* self = static_cast<VulkanContext*>(user);
  std::lock_guard<std::mutex> lock(self->messagesMutex_);
  self->messages_.push_back(std::move(msg));
  return VK_FALSE;  // never abort the call that triggered the message
}

size_t VulkanContext::ValidationMessageCount() const {
  std::lock_guard<std::mutex> lock(messagesMutex_);
  return messages_.size();
}

std::vector<std::string> VulkanContext::ValidationMessages() const {
  std::lock_guard<std::mutex> lock(messagesMutex_);
  return messages_;
}

void VulkanContext::ClearValidationMessages() {
  std::lock_guard<std::mutex> lock(messagesMutex_);
  messages_.clear();
}

VkCommandBuffer VulkanContext::BeginOneShot() {
  auto alloc = VkInit<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
  alloc.commandPool = commandPool;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  std::lock_guard<std::mutex> lock(submitMutex_);
  Check(vkAllocateCommandBuffers(device, &alloc, &cmd), "vkAllocateCommandBuffers");
  auto begin = VkInit<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VkResult r = vkBeginCommandBuffer(cmd, &begin);
  if (r != VK_SUCCESS) {
    vkFreeCommandBuffers(device, commandPool, 1, &cmd);
    Check(r, "vkBeginCommandBuffer");
  }
  return cmd;
}

void VulkanContext::SubmitAndWait(VkCommandBuffer cmd) {
  // Make all device writes visible to the host, so mapped reads after this call see them.
  auto toHost = VkInit<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  toHost.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0,
                       nullptr, 0, nullptr);

  VkFence fence = VK_NULL_HANDLE;
  // Frees the command buffer and fence on every path, including throws.
  struct Cleanup {
    VulkanContext* ctx;
    VkCommandBuffer cmd;
    VkFence& fence;
    ~Cleanup() {
      if (fence) vkDestroyFence(ctx->device, fence, nullptr);
      std::lock_guard<std::mutex> lock(ctx->submitMutex_);
      vkFreeCommandBuffers(ctx->device, ctx->commandPool, 1, &cmd);
    }
  } cleanup{this, cmd, fence};

  Check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  auto fenceInfo = VkInit<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
  Check(vkCreateFence(device, &fenceInfo, nullptr, &fence), "vkCreateFence");
  auto submit = VkInit<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  {
    std::lock_guard<std::mutex> lock(submitMutex_);
    Check(vkQueueSubmit(queue, 1, &submit, fence), "vkQueueSubmit");
  }
  Check(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
}

uint32_t VulkanContext::TryFindMemoryType(uint32_t typeBits, VkMemoryPropertyFlags props) const {
  for (uint32_t i = 0; i < memoryProperties_.memoryTypeCount; ++i)
    if ((typeBits & (1u << i)) && (memoryProperties_.memoryTypes[i].propertyFlags & props) == props) return i;
  return UINT32_MAX;
}

uint32_t VulkanContext::FindMemoryType(uint32_t typeBits, VkMemoryPropertyFlags props) const {
  uint32_t i = TryFindMemoryType(typeBits, props);
  if (i == UINT32_MAX) {
    char detail[64];
    std::snprintf(detail, sizeof(detail), "property flags 0x%x, type bits 0x%x", props, typeBits);
    throw Error(std::string("no Vulkan memory type with ") + detail + " on " + DeviceName());
  }
  return i;
}

VkMemoryPropertyFlags VulkanContext::MemoryTypeFlags(uint32_t typeIndex) const {
  return typeIndex < memoryProperties_.memoryTypeCount ? memoryProperties_.memoryTypes[typeIndex].propertyFlags : 0;
}

void VulkanContext::SetObjectName(VkObjectType type, uint64_t handle, const char* name) const {
  if (!setObjectName_ || !name || !*name || !handle) return;
  auto info = VkInit<VkDebugUtilsObjectNameInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT);
  info.objectType = type;
  info.objectHandle = handle;
  info.pObjectName = name;
  setObjectName_(device, &info);
}

// ---- pipeline cache ------------------------------------------------------------------------------

void VulkanContext::LoadPipelineCache() {
  namespace fs = std::filesystem;
  std::string dir;
  if (const char* d = std::getenv("CROSSRT_PIPELINE_CACHE_DIR"); d && *d)
    dir = d;
  else if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x)
    dir = std::string(x) + "/crossrt";
  else if (const char* h = std::getenv("HOME"); h && *h)
    dir = std::string(h) + "/.cache/crossrt";

  if (!dir.empty()) {
    char ids[32];
    std::snprintf(ids, sizeof(ids), "%04x_%04x_", properties.vendorID, properties.deviceID);
    pipelineCachePath_ = (fs::path(dir) / (std::string("pipeline_cache_") + ids +
                                           Hex(properties.pipelineCacheUUID, VK_UUID_SIZE) + ".bin")).string();
  }

  std::vector<char> data;
  if (!pipelineCachePath_.empty()) {
    std::ifstream in(pipelineCachePath_, std::ios::binary);
    if (in) data.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  // Check the header ourselves: some drivers crash or misbehave on foreign cache data.
  if (!data.empty()) {
    VkPipelineCacheHeaderVersionOne header{};
    bool ok = data.size() >= sizeof(header);
    if (ok) {
      std::memcpy(&header, data.data(), sizeof(header));
      ok = header.headerSize >= sizeof(header) && header.headerSize <= data.size() &&
           header.headerVersion == VK_PIPELINE_CACHE_HEADER_VERSION_ONE && header.vendorID == properties.vendorID &&
           header.deviceID == properties.deviceID &&
           std::memcmp(header.pipelineCacheUUID, properties.pipelineCacheUUID, VK_UUID_SIZE) == 0;
    }
    if (!ok) {
      std::fprintf(stderr, "crossrt: ignoring stale pipeline cache %s\n", pipelineCachePath_.c_str());
      data.clear();
    }
  }

  auto info = VkInit<VkPipelineCacheCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO);
  info.initialDataSize = data.size();
  info.pInitialData = data.empty() ? nullptr : data.data();
  if (vkCreatePipelineCache(device, &info, nullptr, &pipelineCache) != VK_SUCCESS) {
    // Data rejected after all: start empty.
    info.initialDataSize = 0;
    info.pInitialData = nullptr;
    Check(vkCreatePipelineCache(device, &info, nullptr, &pipelineCache), "vkCreatePipelineCache");
  }
}

void VulkanContext::SavePipelineCache() {
  if (!pipelineCache || pipelineCachePath_.empty()) return;
  namespace fs = std::filesystem;
  size_t size = 0;
  if (vkGetPipelineCacheData(device, pipelineCache, &size, nullptr) != VK_SUCCESS || size == 0) return;
  std::vector<char> data(size);
  if (vkGetPipelineCacheData(device, pipelineCache, &size, data.data()) != VK_SUCCESS) return;
  data.resize(size);

  // Write a unique temporary file then rename: concurrent processes never see a torn file.
  std::error_code ec;
  fs::path path(pipelineCachePath_);
  fs::create_directories(path.parent_path(), ec);
  fs::path tmp = path;
  tmp += ".tmp" + std::to_string(reinterpret_cast<uintptr_t>(this));
  bool ok = false;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (out) {
      out.write(data.data(), static_cast<std::streamsize>(data.size()));
      ok = static_cast<bool>(out);
    }
  }
  if (ok) {
    fs::rename(tmp, path, ec);
    ok = !ec;
  }
  if (!ok) {
    fs::remove(tmp, ec);
    std::fprintf(stderr, "crossrt: could not save the pipeline cache to %s\n", pipelineCachePath_.c_str());
  }
}

}  // namespace crossrt
