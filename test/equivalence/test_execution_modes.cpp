// Execution modes (paper 2.1 and 4.4): a control function whose thread loop calls several kernels, passing
// per-thread locals between them, runs on the GPU as one megakernel or as one dispatch per kernel
// call (wavefront, the locals kept in buffers). The original, _CPU, _ISPC (whose thread loops run
// the kernels' C++ on all cores, as _CPU's do) and _Vulkan in both modes must agree. SpherePaths (the sphere_paths example) is a 2D loop of path-tracing kernels; Walkers a 1D
// loop with a struct of state, translated with EXECUTION_MODE megakernel.
#include "SpherePaths.h"
#include "SpherePaths_CPU.h"
#include "SpherePaths_Vulkan.h"
#ifdef CROSSRT_HAS_ISPC
#include "SpherePaths_ISPC.h"
#include "Walkers_ISPC.h"
#endif
#include "TestSupport.h"
#include "Walkers.h"
#include "Walkers_CPU.h"
#include "Walkers_Vulkan.h"

#include <cmath>

namespace
{
std::vector<float4> RenderPaths(SpherePaths& renderer, uint32_t w, uint32_t h, int samples)
{
  std::vector<float4> pixels(size_t(w) * h, float4(-1.0f));
  renderer.m_maxDepth = 3;
  renderer.CommitDeviceData();
  renderer.Render(w, h, samples, pixels.data());
  return pixels;
}

// Pixels whose channels differ by more than `tolerance`.
size_t DifferentPixels(const std::vector<float4>& a, const std::vector<float4>& b, float tolerance)
{
  size_t count = 0;
  for (size_t i = 0; i < a.size(); ++i)
    if (!(std::fabs(a[i].x - b[i].x) <= tolerance) || !(std::fabs(a[i].y - b[i].y) <= tolerance) || !(std::fabs(a[i].z - b[i].z) <= tolerance) ||
        a[i].w != b[i].w)  // (written so that a NaN counts)
      ++count;
  return count;
}
}  // namespace

TEST_CASE("Execution modes: a 2D thread loop of path-tracing kernels gives the same image as a megakernel and as wavefront dispatches", "[equivalence][modes]")
{
  const uint32_t w = 40, h = 24;
  const int samples = 3;
  SpherePaths original;
  const std::vector<float4> expected = RenderPaths(original, w, h, samples);
  // Not an empty picture: the light, the sky and the spheres give a range of values.
  float lo = 1e30f, hi = -1e30f;
  for (auto& p : expected)
    lo = std::min(lo, p.y), hi = std::max(hi, p.y);
  REQUIRE(lo >= 0.0f);
  REQUIRE(hi > lo + 0.5f);

  auto cpu = CreateSpherePaths_CPU();
  CHECK(DifferentPixels(expected, RenderPaths(*cpu, w, h, samples), 0.0f) == 0);  // the same code, per pixel
#ifdef CROSSRT_HAS_ISPC
  CHECK(DifferentPixels(expected, RenderPaths(*CreateSpherePaths_ISPC(), w, h, samples), 0.0f) == 0);
#endif

  auto ctx = ValidatedContext();
  if (!ctx)
    return;
  SpherePaths_Vulkan gpu(ctx);
  REQUIRE(gpu.GetExecutionMode() == crossrt::ExecutionMode::Wavefront);  // the default without EXECUTION_MODE
  const std::vector<float4> wavefront = RenderPaths(gpu, w, h, samples);
  gpu.SetExecutionMode(crossrt::ExecutionMode::Megakernel);
  const std::vector<float4> megakernel = RenderPaths(gpu, w, h, samples);
  RequireNoValidationMessages(ctx);
  // The GPU rounds sqrt, sin and cos differently from the CPU in the last bits; a path whose ray
  // then grazes a sphere on the other side may take another way. A few pixels may differ, no more.
  const size_t allowed = expected.size() / 100;
  CHECK(DifferentPixels(expected, wavefront, 1e-3f) <= allowed);
  CHECK(DifferentPixels(expected, megakernel, 1e-3f) <= allowed);
  // Both modes run the same functions on the same device.
  CHECK(DifferentPixels(wavefront, megakernel, 1e-5f) <= allowed);

  // A second size reuses and grows the per-thread buffers of the wavefront mode.
  gpu.SetExecutionMode(crossrt::ExecutionMode::Wavefront);
  SpherePaths bigger;
  CHECK(DifferentPixels(RenderPaths(bigger, 2 * w, h + 7, 1), RenderPaths(gpu, 2 * w, h + 7, 1), 1e-3f) <= 2 * w * (h + 7) / 100);
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Execution modes: a 1D thread loop with struct state starts as a megakernel when translated with EXECUTION_MODE megakernel", "[equivalence][modes]")
{
  const int n = 1000, steps = 37;
  std::vector<float> coords = RandomFloats(3 * n, 11u, -0.9f, 0.9f);
  std::vector<float4> starts(n);
  for (int i = 0; i < n; ++i)
    starts[i] = float4(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2], 0.0f);
  auto walk = [&](Walkers& walkers, std::vector<float4>& ends, std::vector<int>& bounces) {
    ends.assign(n, float4(0.0f));
    bounces.assign(n, -1);
    walkers.Walk(n, steps, starts.data(), ends.data(), bounces.data());
  };
  Walkers original;
  std::vector<float4> expectedEnds;
  std::vector<int> expectedBounces;
  walk(original, expectedEnds, expectedBounces);
  int totalBounces = 0;
  for (int b : expectedBounces)
    totalBounces += b;
  REQUIRE(totalBounces > n);  // the walls matter

  auto compare = [&](Walkers& walkers) {
    std::vector<float4> ends;
    std::vector<int> bounces;
    walk(walkers, ends, bounces);
    size_t different = 0;
    for (int i = 0; i < n; ++i)
      if (bounces[i] != expectedBounces[i] || !Close(ends[i].x, expectedEnds[i].x, 1e-4f) || !Close(ends[i].y, expectedEnds[i].y, 1e-4f) ||
          !Close(ends[i].z, expectedEnds[i].z, 1e-4f) || !Close(ends[i].w, expectedEnds[i].w, 1e-4f))
        ++different;
    return different;
  };
  auto cpu = CreateWalkers_CPU();
  CHECK(compare(*cpu) == 0);
#ifdef CROSSRT_HAS_ISPC
  CHECK(compare(*CreateWalkers_ISPC()) == 0);
#endif
  auto ctx = ValidatedContext();
  if (!ctx)
    return;
  Walkers_Vulkan gpu(ctx);
  REQUIRE(gpu.GetExecutionMode() == crossrt::ExecutionMode::Megakernel);
  // A walker that meets a wall within a rounding error of the CPU's may bounce one step apart.
  CHECK(compare(gpu) <= 2);
  gpu.SetExecutionMode(crossrt::ExecutionMode::Wavefront);
  CHECK(compare(gpu) <= 2);
  RequireNoValidationMessages(ctx);
}
