// The conformance suite: small classes written as users write them, in the paper's conventions
// (cases/), each run as written, as <Class>_CPU, as <Class>_Vulkan (lavapipe, or the device
// CROSSRT_DEVICE names, with validation layers on) and, where an ISPC compiler was found, as
// <Class>_ISPC, and compared. Each check_*.cpp registers the
// cases of one theme; main.cpp runs them all and prints which constructs pass.
#pragma once
#include <crossrt/VulkanRuntime.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace conformance {

// What a run shows: the numbers it produced (outputs, members read back), compared across backends.
using Outputs = std::vector<double>;

struct Run {
  bool ran = false;
  std::string error;  // what it threw, when it did
  Outputs outputs;
};

struct Case {
  std::string construct;  // what the class exercises
  std::string files;      // where it is, under cases/
  double tolerance = 1e-5;  // |translated - original| <= tolerance * max(1, |original|), per output
  std::function<Run()> original, cpu, vulkan, ispc;  // ispc: empty where the build has no ISPC classes
  // Set when the Vulkan backend refuses the class by design: the diagnostic it gives (checked by
  // translating the class again; the build translates it for the CPU only).
  std::string vulkanRefusal, className;
};

std::vector<Case>& Registry();
struct Register {
  explicit Register(Case c) { Registry().push_back(std::move(c)); }
};

// The Vulkan device the suite runs on, with validation layers on; null when the machine has no
// Vulkan driver at all (the Vulkan column then says so).
std::shared_ptr<crossrt::VulkanContext> Context();

// Runs `work` on the object `make` creates, catching what either throws.
template <class T>
Run RunOn(const std::function<std::shared_ptr<T>()>& make, const std::function<Outputs(T&)>& work) {
  Run r;
  try {
    std::shared_ptr<T> object = make();
    if (!object) {
      r.error = "no object";
      return r;
    }
    r.outputs = work(*object);
    r.ran = true;
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  return r;
}

// A case from the ways of making the class (as written, _CPU, _Vulkan, _ISPC) and what to run on it.
template <class T>
Case MakeCase(std::string construct, std::string files, double tolerance, std::function<std::shared_ptr<T>()> original,
              std::function<std::shared_ptr<T>()> cpu, std::function<std::shared_ptr<T>()> vulkan,
              std::function<std::shared_ptr<T>()> ispc, std::function<Outputs(T&)> work) {
  Case c;
  c.construct = std::move(construct);
  c.files = std::move(files);
  c.tolerance = tolerance;
  c.original = [=] { return RunOn<T>(original, work); };
  c.cpu = [=] { return RunOn<T>(cpu, work); };
  if (vulkan) c.vulkan = [=] { return RunOn<T>(vulkan, work); };
  if (ispc) c.ispc = [=] { return RunOn<T>(ispc, work); };
  return c;
}

template <class V>
void Append(Outputs& out, const V& values) {
  for (auto& v : values) out.push_back(double(v));
}

}  // namespace conformance

// The constructions of Class with the same arguments: as written, Class_CPU, Class_Vulkan on the
// suite's device, and Class_ISPC where the build has it (CONFORMANCE_ISPC).
#ifdef CONFORMANCE_ISPC
#define CONFORMANCE_ISPC_MAKER(Class, ...) [] { return Create##Class##_ISPC(__VA_ARGS__); }
#else
#define CONFORMANCE_ISPC_MAKER(Class, ...) std::function<std::shared_ptr<Class>()>()
#endif
#define CONFORMANCE_MAKERS(Class, ...)                                                               \
  [] { return std::make_shared<Class>(__VA_ARGS__); }, [] { return Create##Class##_CPU(__VA_ARGS__); }, \
      [] { return Create##Class##_Vulkan(conformance::Context(), ##__VA_ARGS__); }, CONFORMANCE_ISPC_MAKER(Class, __VA_ARGS__)
