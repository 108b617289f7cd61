// Shared helpers of the equivalence tests: a validated Vulkan context and tolerant comparisons.
#pragma once
#include <catch2/catch.hpp>
#include <crossrt/VulkanRuntime.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

// Lavapipe (or the device CROSSRT_DEVICE names) with validation layers on. Returns null, with a
// visible warning, only when the machine has no Vulkan driver at all.
inline std::shared_ptr<crossrt::VulkanContext> ValidatedContext()
{
  static std::shared_ptr<crossrt::VulkanContext> ctx = [] {
    crossrt::ContextOptions options;
    options.validation = true;
    const char* device = std::getenv("CROSSRT_DEVICE");
    options.device = device ? device : "";
    try {
      return crossrt::VulkanContext::Create(options);
    } catch (const crossrt::NoDeviceError& e) {
      return std::shared_ptr<crossrt::VulkanContext>();
    }
  }();
  if (!ctx) WARN("skipping the Vulkan part: no Vulkan driver on this machine (install mesa-vulkan-drivers)");
  return ctx;
}

// Whether the device divides and takes square roots correctly rounded, as the CPU does. Lavapipe
// runs LLVM's IEEE operations; GPUs may be 2.5 ulp off in a division and more in a square root
// (Vulkan's precision rules), so results that hinge on the last bit of a quotient can differ there.
inline bool RoundsLikeTheCpu(const crossrt::VulkanContext& ctx)
{
  return ctx.DeviceName().find("llvmpipe") != std::string::npos;
}

// n floats uniform in [lo, hi), the same for a given seed.
inline std::vector<float> RandomFloats(int n, unsigned seed, float lo, float hi)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  std::vector<float> v(n);
  for (auto& x : v) x = u(rng);
  return v;
}

// Any validation message fails the test.
inline void RequireNoValidationMessages(const std::shared_ptr<crossrt::VulkanContext>& ctx)
{
  if (!ctx) return;
  auto messages = ctx->ValidationMessages();
  for (auto& m : messages) UNSCOPED_INFO(m);
  REQUIRE(messages.empty());
  ctx->ClearValidationMessages();
}

// |a - b| <= rel * max(1, |a|): relative for large values, absolute near zero.
inline bool Close(float a, float b, float rel)
{
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return std::fabs(a - b) <= rel * std::max(1.0f, std::fabs(a));
}

template <typename T>
size_t CountMismatches(const std::vector<T>& expected, const std::vector<T>& actual, float rel)
{
  size_t bad = 0;
  for (size_t i = 0; i < expected.size(); ++i)
    if (!Close(float(expected[i]), float(actual[i]), rel)) ++bad;
  return bad;
}
