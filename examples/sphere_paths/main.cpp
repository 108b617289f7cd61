// Path tracing through a thread loop of several kernels (SpherePaths::Render), four ways: the class
// as written (1 thread), SpherePaths_CPU (all cores), and SpherePaths_Vulkan in both execution
// modes, wavefront (one dispatch per kernel call) and megakernel (the whole loop in one shader).
// Prints a table of times and of pixels that differ from the original, and writes the image.
//   sphere_paths [output image] [--size N] [--samples S] [--depth D]
#include "Image2D.h"
#include "SpherePaths.h"
#include "SpherePaths_CPU.h"
#include "SpherePaths_Vulkan.h"

#include "CommandLine.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

using LiteMath::float4;

namespace {

struct Run
{
  std::string name;
  std::shared_ptr<SpherePaths> renderer;
  std::vector<float4> pixels;
  double ms = 0.0;
};

// Linear radiance to an 8-bit sRGB-like channel (gamma 2.2, clamped).
uint32_t Channel(float v) { return uint32_t(std::lround(255.0f * std::pow(std::clamp(v, 0.0f, 1.0f), 1.0f / 2.2f))); }

uint32_t Rgba8(const float4& c) { return Channel(c.x) | Channel(c.y) << 8 | Channel(c.z) << 16 | 255u << 24; }

// Pixels whose 8-bit channels differ by more than 2.
size_t DifferingPixels(const std::vector<float4>& a, const std::vector<float4>& b)
{
  size_t count = 0;
  for (size_t i = 0; i < a.size(); ++i)
  {
    const uint32_t x = Rgba8(a[i]), y = Rgba8(b[i]);
    for (int c = 0; c < 3; ++c)
      if (std::abs(int((x >> (8 * c)) & 255u) - int((y >> (8 * c)) & 255u)) > 2)
      {
        ++count;
        break;
      }
  }
  return count;
}

}  // namespace

int main(int argc, char** argv)
{
  std::string outPath = "sphere_paths.png";
  int size = 256, samples = 16, depth = 4;
  crossrt::CommandLine app("sphere_paths",
                           "Path traces spheres with the original class, SpherePaths_CPU and SpherePaths_Vulkan (megakernel and\n"
                           "wavefront); writes OUTPUT.png. Exits non-zero when they differ.");
  app.add_option("OUTPUT.png", outPath, "the image");
  app.add_option("--size", size, "width and height in pixels")->check(crossrt::Positive());
  app.add_option("--samples", samples, "paths per pixel")->check(crossrt::Positive());
  app.add_option("--depth", depth, "bounces")->check(crossrt::NonNegative());
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;

  std::vector<Run> runs;
  runs.push_back({"original (1 thread)", std::make_shared<SpherePaths>(), {}});
  runs.push_back({"SpherePaths_CPU (all cores)", CreateSpherePaths_CPU(), {}});
  try
  {
    auto ctx = crossrt::VulkanContext::CreateDefault();
    auto wavefront = std::make_shared<SpherePaths_Vulkan>(ctx);
    wavefront->SetExecutionMode(crossrt::ExecutionMode::Wavefront);
    runs.push_back({"SpherePaths_Vulkan, wavefront", wavefront, {}});
    auto megakernel = std::make_shared<SpherePaths_Vulkan>(ctx);
    megakernel->SetExecutionMode(crossrt::ExecutionMode::Megakernel);
    runs.push_back({"SpherePaths_Vulkan, megakernel", megakernel, {}});
    std::printf("device: %s\n", ctx->DeviceName().c_str());
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "sphere_paths: Vulkan is not available, skipping SpherePaths_Vulkan: %s\n", e.what());
  }
  const uint32_t side = uint32_t(size);
  try
  {
    for (Run& r : runs)
    {
      r.renderer->m_maxDepth = depth;
      r.renderer->CommitDeviceData();
      r.pixels.resize(size_t(side) * side);
      r.renderer->Render(side, side, samples, r.pixels.data());  // warm-up (uploads the scene, sizes buffers)
      const auto t0 = std::chrono::steady_clock::now();
      r.renderer->Render(side, side, samples, r.pixels.data());
      r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    }
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "sphere_paths: %s\n", e.what());
    return 1;
  }

  const double paths = double(side) * side * samples;
  std::printf("%dx%d pixels, %d paths per pixel, up to %d bounces, %zu spheres\n\n", size, size, samples, depth, runs[0].renderer->m_spheres.size());
  std::printf("| %-32s | %9s | %13s | %24s |\n|%s|\n", "renderer", "ms", "Mpaths/s", "pixels != original", std::string(90, '-').c_str());
  size_t worst = 0;
  for (Run& r : runs)
  {
    const size_t diff = DifferingPixels(r.pixels, runs[0].pixels);
    worst = std::max(worst, diff);
    std::printf("| %-32s | %9.1f | %13.2f | %15zu (%5.2f%%) |\n", r.name.c_str(), r.ms, paths / r.ms * 1e-3, diff,
                100.0 * double(diff) / double(r.pixels.size()));
  }
  std::vector<uint32_t> rgba(runs.back().pixels.size());
  std::transform(runs.back().pixels.begin(), runs.back().pixels.end(), rgba.begin(), Rgba8);
  LiteImage::Image2D<uint32_t> image(side, side, rgba.data());
  if (!LiteImage::SaveImage(outPath.c_str(), image))
    return 1;
  std::printf("\nwrote %s (from %s)\n", outPath.c_str(), runs.back().name.c_str());
  // A path whose float rounding differs at a grazing hit may take another way; more than 0.5% of
  // the pixels would mean a real difference.
  return double(worst) <= 0.005 * double(size) * size ? 0 : 1;
}
