// vk_watertight: does a Vulkan driver's ray/triangle test leak rays between triangles that share
// an edge or a vertex? Plain Vulkan, no CrossRT: the smallest program that shows what a driver does,
// so that CrossRT's tests can tell the driver's behaviour from CrossRT's.
//
// A closed mesh (an icosphere: every edge shared by two triangles, every vertex by five or six) in
// one bottom-level acceleration structure, and rays with ray queries from its centre and from
// random points inside: to each vertex, to each edge's midpoint, and in random directions. A watertight test (as the spec asks
// implementations to be, and as NVIDIA's hardware is) never lets a ray from inside a closed mesh
// leave it. Prints the device, the misses per kind of ray, and "watertight: yes" or "no".
// Exits 77 (skipped) without a device that has ray queries, 1 on a Vulkan error, and 1 when a
// random ray (one that meets no edge or vertex) misses: that is no watertightness question.
#include <cstdint>

#include "watertight.spv.h"
#include "CommandLine.h"

#include <vulkan/vulkan.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace {

// A zeroed Vulkan struct with its sType and pNext set.
template <class T>
T Init(VkStructureType type, const void* next = nullptr) {
  T t{};
  t.sType = type;
  t.pNext = const_cast<void*>(next);
  return t;
}

void Check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) {
    std::fprintf(stderr, "vk_watertight: %s failed: VkResult %d\n", what, int(r));
    std::exit(1);
  }
}

struct Vec3 { float x, y, z; };

// An icosphere of `levels` subdivisions: shared vertices (by index), every edge in two triangles.
void Icosphere(int levels, std::vector<Vec3>& vertices, std::vector<uint32_t>& indices) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
              {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  indices = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,
             3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
  auto normalise = [](Vec3 v) {
    const float l = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    return Vec3{v.x / l, v.y / l, v.z / l};
  };
  for (Vec3& v : vertices) v = normalise(v);
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> middle;
    auto mid = [&](uint32_t a, uint32_t b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = middle.find(key);
      if (it != middle.end()) return it->second;
      const Vec3 &p = vertices[a], &q = vertices[b];
      vertices.push_back(normalise({p.x + q.x, p.y + q.y, p.z + q.z}));
      return middle[key] = uint32_t(vertices.size() - 1);
    };
    std::vector<uint32_t> next;
    for (size_t i = 0; i < indices.size(); i += 3) {
      const uint32_t a = indices[i], b = indices[i + 1], c = indices[i + 2];
      const uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    indices = next;
  }
}

struct Device {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t family = 0;
  VkPhysicalDeviceMemoryProperties memory{};
  PFN_vkGetAccelerationStructureBuildSizesKHR getBuildSizes = nullptr;
  PFN_vkCreateAccelerationStructureKHR createAs = nullptr;
  PFN_vkDestroyAccelerationStructureKHR destroyAs = nullptr;
  PFN_vkCmdBuildAccelerationStructuresKHR cmdBuildAs = nullptr;
  PFN_vkGetAccelerationStructureDeviceAddressKHR asAddress = nullptr;
};

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkDeviceAddress address = 0;
};

// A host-visible, coherent, mapped buffer with a device address.
Buffer MakeBuffer(const Device& d, VkDeviceSize size, VkBufferUsageFlags usage) {
  Buffer b;
  auto info = Init<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  info.size = size;
  info.usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  Check(vkCreateBuffer(d.device, &info, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(d.device, b.buffer, &req);
  const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  uint32_t type = UINT32_MAX;
  for (uint32_t i = 0; i < d.memory.memoryTypeCount && type == UINT32_MAX; ++i)
    if ((req.memoryTypeBits & (1u << i)) && (d.memory.memoryTypes[i].propertyFlags & want) == want) type = i;
  if (type == UINT32_MAX) Check(VK_ERROR_OUT_OF_DEVICE_MEMORY, "finding host-visible memory");
  auto flags = Init<VkMemoryAllocateFlagsInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO);
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  auto alloc = Init<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags);
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = type;
  Check(vkAllocateMemory(d.device, &alloc, nullptr, &b.memory), "vkAllocateMemory");
  Check(vkBindBufferMemory(d.device, b.buffer, b.memory, 0), "vkBindBufferMemory");
  Check(vkMapMemory(d.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
  auto addressInfo = Init<VkBufferDeviceAddressInfo>(VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO);
  addressInfo.buffer = b.buffer;
  b.address = vkGetBufferDeviceAddress(d.device, &addressInfo);
  return b;
}

void FreeBuffer(const Device& d, Buffer& b) {
  vkDestroyBuffer(d.device, b.buffer, nullptr);
  vkFreeMemory(d.device, b.memory, nullptr);
}

bool HasExtension(VkPhysicalDevice pd, const char* name) {
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> list(n);
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, list.data());
  for (auto& e : list)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

// The first device with ray queries, with the validation layers where they are installed.
bool OpenDevice(Device& d) {
  auto app = Init<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  app.pApplicationName = "vk_watertight";
  app.apiVersion = VK_API_VERSION_1_2;
  uint32_t layerCount = 0;
  vkEnumerateInstanceLayerProperties(&layerCount, nullptr);
  std::vector<VkLayerProperties> layers(layerCount);
  vkEnumerateInstanceLayerProperties(&layerCount, layers.data());
  const char* validation = "VK_LAYER_KHRONOS_validation";
  bool hasValidation = false;
  for (auto& l : layers) hasValidation = hasValidation || std::strcmp(l.layerName, validation) == 0;
  auto info = Init<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
  info.pApplicationInfo = &app;
  info.enabledLayerCount = hasValidation ? 1 : 0;
  info.ppEnabledLayerNames = &validation;
  Check(vkCreateInstance(&info, nullptr, &d.instance), "vkCreateInstance");
  uint32_t n = 0;
  vkEnumeratePhysicalDevices(d.instance, &n, nullptr);
  std::vector<VkPhysicalDevice> devices(n);
  vkEnumeratePhysicalDevices(d.instance, &n, devices.data());
  for (VkPhysicalDevice pd : devices)
    if (HasExtension(pd, VK_KHR_RAY_QUERY_EXTENSION_NAME) && HasExtension(pd, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME)) {
      d.physical = pd;
      break;
    }
  if (!d.physical) return false;
  uint32_t families = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(d.physical, &families, nullptr);
  std::vector<VkQueueFamilyProperties> props(families);
  vkGetPhysicalDeviceQueueFamilyProperties(d.physical, &families, props.data());
  for (uint32_t i = 0; i < families; ++i)
    if (props[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
      d.family = i;
      break;
    }
  auto rayQuery = Init<VkPhysicalDeviceRayQueryFeaturesKHR>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR);
  rayQuery.rayQuery = VK_TRUE;
  auto as = Init<VkPhysicalDeviceAccelerationStructureFeaturesKHR>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, &rayQuery);
  as.accelerationStructure = VK_TRUE;
  auto v12 = Init<VkPhysicalDeviceVulkan12Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &as);
  v12.bufferDeviceAddress = VK_TRUE;
  const float priority = 1.0f;
  auto queue = Init<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
  queue.queueFamilyIndex = d.family;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  const char* extensions[] = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_RAY_QUERY_EXTENSION_NAME,
                              VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
  auto dinfo = Init<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &v12);
  dinfo.queueCreateInfoCount = 1;
  dinfo.pQueueCreateInfos = &queue;
  dinfo.enabledExtensionCount = 3;
  dinfo.ppEnabledExtensionNames = extensions;
  Check(vkCreateDevice(d.physical, &dinfo, nullptr, &d.device), "vkCreateDevice");
  vkGetDeviceQueue(d.device, d.family, 0, &d.queue);
  vkGetPhysicalDeviceMemoryProperties(d.physical, &d.memory);
  d.getBuildSizes = PFN_vkGetAccelerationStructureBuildSizesKHR(vkGetDeviceProcAddr(d.device, "vkGetAccelerationStructureBuildSizesKHR"));
  d.createAs = PFN_vkCreateAccelerationStructureKHR(vkGetDeviceProcAddr(d.device, "vkCreateAccelerationStructureKHR"));
  d.destroyAs = PFN_vkDestroyAccelerationStructureKHR(vkGetDeviceProcAddr(d.device, "vkDestroyAccelerationStructureKHR"));
  d.cmdBuildAs = PFN_vkCmdBuildAccelerationStructuresKHR(vkGetDeviceProcAddr(d.device, "vkCmdBuildAccelerationStructuresKHR"));
  d.asAddress = PFN_vkGetAccelerationStructureDeviceAddressKHR(vkGetDeviceProcAddr(d.device, "vkGetAccelerationStructureDeviceAddressKHR"));
  return true;
}

// Records, submits and waits for the commands `record` records.
template <class F>
void Submit(const Device& d, VkCommandPool pool, F record) {
  auto alloc = Init<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
  alloc.commandPool = pool;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cmd;
  Check(vkAllocateCommandBuffers(d.device, &alloc, &cmd), "vkAllocateCommandBuffers");
  auto begin = Init<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  Check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
  record(cmd);
  Check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  auto submit = Init<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  Check(vkQueueSubmit(d.queue, 1, &submit, VK_NULL_HANDLE), "vkQueueSubmit");
  Check(vkQueueWaitIdle(d.queue), "vkQueueWaitIdle");
  vkFreeCommandBuffers(d.device, pool, 1, &cmd);
}

// One acceleration structure of `type` over `geometry`, built and waited for.
struct Level {
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
  Buffer storage;
};
Level Build(const Device& d, VkCommandPool pool, VkAccelerationStructureTypeKHR type,
            const VkAccelerationStructureGeometryKHR& geometry, uint32_t primitives) {
  auto build = Init<VkAccelerationStructureBuildGeometryInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR);
  build.type = type;
  build.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  build.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  build.geometryCount = 1;
  build.pGeometries = &geometry;
  auto sizes = Init<VkAccelerationStructureBuildSizesInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR);
  d.getBuildSizes(d.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &build, &primitives, &sizes);
  Level level;
  level.storage = MakeBuffer(d, sizes.accelerationStructureSize, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  auto info = Init<VkAccelerationStructureCreateInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR);
  info.buffer = level.storage.buffer;
  info.size = sizes.accelerationStructureSize;
  info.type = type;
  Check(d.createAs(d.device, &info, nullptr, &level.handle), "vkCreateAccelerationStructureKHR");
  Buffer scratch = MakeBuffer(d, sizes.buildScratchSize + 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  build.dstAccelerationStructure = level.handle;
  build.scratchData.deviceAddress = (scratch.address + 255) / 256 * 256;
  VkAccelerationStructureBuildRangeInfoKHR range{primitives, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  Submit(d, pool, [&](VkCommandBuffer cmd) { d.cmdBuildAs(cmd, 1, &build, &ranges); });
  FreeBuffer(d, scratch);
  return level;
}

}  // namespace

int main(int argc, char** argv) {
  crossrt::CommandLine app("vk_watertight",
                           "Traces rays with ray queries from inside a closed mesh (an icosphere) through its vertices, its edges'\n"
                           "midpoints and random directions on the first Vulkan device with ray queries, and prints how many leave\n"
                           "the mesh without a hit: 'watertight: yes' when none does.");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  Device d;
  if (!OpenDevice(d)) {
    std::printf("vk_watertight: no Vulkan device with ray queries: skipped\n");
    return 77;
  }
  auto driver = Init<VkPhysicalDeviceDriverProperties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES);
  auto props = Init<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver);
  vkGetPhysicalDeviceProperties2(d.physical, &props);
  std::printf("device: %s (%s %s)\n", props.properties.deviceName, driver.driverName, driver.driverInfo);

  // The mesh, as a triangle soup whose shared corners are the very same floats.
  std::vector<Vec3> vertices;
  std::vector<uint32_t> indices;
  Icosphere(3, vertices, indices);
  const uint32_t triangles = uint32_t(indices.size() / 3);
  Buffer soup = MakeBuffer(d, sizeof(Vec3) * indices.size(), VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  for (size_t i = 0; i < indices.size(); ++i) static_cast<Vec3*>(soup.mapped)[i] = vertices[indices[i]];

  // The rays, from the centre and from random points inside: to every vertex, to every edge's
  // midpoint, and in random directions.
  std::vector<float> dirs;  // origin, direction
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> inside(-0.5f, 0.5f);
  std::normal_distribution<float> normal;
  std::vector<int> kinds;  // 0: to a vertex, 1: to an edge, 2: random
  auto add = [&](int kind, Vec3 o, Vec3 target) {
    dirs.insert(dirs.end(), {o.x, o.y, o.z, 0.0f, target.x - o.x, target.y - o.y, target.z - o.z, 0.0f});
    kinds.push_back(kind);
  };
  for (int from = 0; from < 4; ++from) {
    const Vec3 o = from == 0 ? Vec3{0, 0, 0} : Vec3{inside(rng), inside(rng), inside(rng)};
    for (const Vec3& v : vertices) add(0, o, v);
    for (size_t i = 0; i < indices.size(); i += 3)
      for (int e = 0; e < 3; ++e) {
        const Vec3 &a = vertices[indices[i + e]], &b = vertices[indices[i + (e + 1) % 3]];
        add(1, o, {0.5f * (a.x + b.x), 0.5f * (a.y + b.y), 0.5f * (a.z + b.z)});
      }
  }
  for (int i = 0; i < 20000; ++i) add(2, {0, 0, 0}, {normal(rng), normal(rng), normal(rng)});
  const uint32_t rays = uint32_t(kinds.size());

  auto poolInfo = Init<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  poolInfo.queueFamilyIndex = d.family;
  VkCommandPool pool;
  Check(vkCreateCommandPool(d.device, &poolInfo, nullptr, &pool), "vkCreateCommandPool");

  auto mesh = Init<VkAccelerationStructureGeometryKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR);
  mesh.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  mesh.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  mesh.geometry.triangles.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  mesh.geometry.triangles.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  mesh.geometry.triangles.vertexData.deviceAddress = soup.address;
  mesh.geometry.triangles.vertexStride = sizeof(Vec3);
  mesh.geometry.triangles.maxVertex = uint32_t(indices.size() - 1);
  mesh.geometry.triangles.indexType = VK_INDEX_TYPE_NONE_KHR;
  Level bottom = Build(d, pool, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, mesh, triangles);

  Buffer instance = MakeBuffer(d, sizeof(VkAccelerationStructureInstanceKHR), VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  VkAccelerationStructureInstanceKHR record{};
  record.transform.matrix[0][0] = record.transform.matrix[1][1] = record.transform.matrix[2][2] = 1.0f;
  record.mask = 0xFF;
  record.flags = VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR;
  auto bottomAddress = Init<VkAccelerationStructureDeviceAddressInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR);
  bottomAddress.accelerationStructure = bottom.handle;
  record.accelerationStructureReference = d.asAddress(d.device, &bottomAddress);
  std::memcpy(instance.mapped, &record, sizeof(record));
  auto instances = Init<VkAccelerationStructureGeometryKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR);
  instances.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  instances.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  instances.geometry.instances.data.deviceAddress = instance.address;
  Level top = Build(d, pool, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, instances, 1);

  Buffer rayBuffer = MakeBuffer(d, sizeof(float) * dirs.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memcpy(rayBuffer.mapped, dirs.data(), sizeof(float) * dirs.size());
  Buffer hitBuffer = MakeBuffer(d, 8 * size_t(rays), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

  // The compute pipeline of watertight.comp: the scene and two storage buffers.
  const VkDescriptorSetLayoutBinding bindings[] = {
      {0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr}};
  auto setInfo = Init<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
  setInfo.bindingCount = 3;
  setInfo.pBindings = bindings;
  VkDescriptorSetLayout setLayout;
  Check(vkCreateDescriptorSetLayout(d.device, &setInfo, nullptr, &setLayout), "vkCreateDescriptorSetLayout");
  const VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(uint32_t)};
  auto layoutInfo = Init<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
  layoutInfo.setLayoutCount = 1;
  layoutInfo.pSetLayouts = &setLayout;
  layoutInfo.pushConstantRangeCount = 1;
  layoutInfo.pPushConstantRanges = &push;
  VkPipelineLayout layout;
  Check(vkCreatePipelineLayout(d.device, &layoutInfo, nullptr, &layout), "vkCreatePipelineLayout");
  auto moduleInfo = Init<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
  moduleInfo.codeSize = sizeof(kWatertightSpv);
  moduleInfo.pCode = kWatertightSpv;
  VkShaderModule module;
  Check(vkCreateShaderModule(d.device, &moduleInfo, nullptr, &module), "vkCreateShaderModule");
  auto pipelineInfo = Init<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
  pipelineInfo.stage = Init<VkPipelineShaderStageCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
  pipelineInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  pipelineInfo.stage.module = module;
  pipelineInfo.stage.pName = "main";
  pipelineInfo.layout = layout;
  VkPipeline pipeline;
  Check(vkCreateComputePipelines(d.device, VK_NULL_HANDLE, 1, &pipelineInfo, nullptr, &pipeline), "vkCreateComputePipelines");

  const VkDescriptorPoolSize poolSizes[] = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2}};
  auto descriptorPoolInfo = Init<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
  descriptorPoolInfo.maxSets = 1;
  descriptorPoolInfo.poolSizeCount = 2;
  descriptorPoolInfo.pPoolSizes = poolSizes;
  VkDescriptorPool descriptorPool;
  Check(vkCreateDescriptorPool(d.device, &descriptorPoolInfo, nullptr, &descriptorPool), "vkCreateDescriptorPool");
  auto setAlloc = Init<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
  setAlloc.descriptorPool = descriptorPool;
  setAlloc.descriptorSetCount = 1;
  setAlloc.pSetLayouts = &setLayout;
  VkDescriptorSet set;
  Check(vkAllocateDescriptorSets(d.device, &setAlloc, &set), "vkAllocateDescriptorSets");
  auto sceneWrite = Init<VkWriteDescriptorSetAccelerationStructureKHR>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR);
  sceneWrite.accelerationStructureCount = 1;
  sceneWrite.pAccelerationStructures = &top.handle;
  const VkDescriptorBufferInfo rayInfo{rayBuffer.buffer, 0, VK_WHOLE_SIZE}, hitInfo{hitBuffer.buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet writes[3] = {};
  for (uint32_t i = 0; i < 3; ++i) {
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = set;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = bindings[i].descriptorType;
  }
  writes[0].pNext = &sceneWrite;
  writes[1].pBufferInfo = &rayInfo;
  writes[2].pBufferInfo = &hitInfo;
  vkUpdateDescriptorSets(d.device, 3, writes, 0, nullptr);

  Submit(d, pool, [&](VkCommandBuffer cmd) {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(uint32_t), &rays);
    vkCmdDispatch(cmd, (rays + 63) / 64, 1, 1);
  });

  const uint32_t* hits = static_cast<const uint32_t*>(hitBuffer.mapped);
  size_t missed[3] = {0, 0, 0}, count[3] = {0, 0, 0};
  for (uint32_t i = 0; i < rays; ++i) {
    ++count[kinds[i]];
    missed[kinds[i]] += hits[2 * i] == 0xFFFFFFFFu;
  }
  std::printf("%u triangles; rays from inside: %zu to vertices, %zu missed; %zu to edge midpoints, %zu missed; "
              "%zu random, %zu missed\n",
              triangles, count[0], missed[0], count[1], missed[1], count[2], missed[2]);
  std::printf("watertight: %s\n", missed[0] + missed[1] == 0 ? "yes" : "no");

  vkDestroyDescriptorPool(d.device, descriptorPool, nullptr);
  vkDestroyPipeline(d.device, pipeline, nullptr);
  vkDestroyShaderModule(d.device, module, nullptr);
  vkDestroyPipelineLayout(d.device, layout, nullptr);
  vkDestroyDescriptorSetLayout(d.device, setLayout, nullptr);
  d.destroyAs(d.device, top.handle, nullptr);
  d.destroyAs(d.device, bottom.handle, nullptr);
  for (Buffer* b : {&top.storage, &bottom.storage, &soup, &instance, &rayBuffer, &hitBuffer}) FreeBuffer(d, *b);
  vkDestroyCommandPool(d.device, pool, nullptr);
  vkDestroyDevice(d.device, nullptr);
  vkDestroyInstance(d.instance, nullptr);
  if (missed[2] != 0) {
    std::fprintf(stderr, "vk_watertight: %zu random rays from inside the mesh missed it\n", missed[2]);
    return 1;
  }
  return 0;
}
