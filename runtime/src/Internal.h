// Helpers shared by the runtime's source files (not installed).
#pragma once

#include <vulkan/vulkan.h>

namespace crossrt {

// A zeroed Vulkan struct with its sType set: avoids partial aggregate initialization
// (which -Wextra flags) and forgotten pNext/flags.
template <class T>
T VkInit(VkStructureType sType) {
  T t{};
  t.sType = sType;
  return t;
}

}  // namespace crossrt
