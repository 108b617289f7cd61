// Benchmark: sampling an array of textures per thread (TexturedMaterials, the test class) as the
// original single-threaded C++, as TexturedMaterials_CPU (all cores) and as
// TexturedMaterials_Vulkan with each way of sampling the device has: from buffers as LiteImage
// samples (every device; bit for bit the CPU's texels) and with the GPU's samplers (devices with
// descriptor indexing). Speed against accuracy: each row prints its largest difference from the
// original. Times are medians of the repeats after a warm-up, all from this one run.
//   bench_textures [hits] [textures] [texture side]
#include "BenchSupport.h"
#include "TexturedMaterials.h"
#include "TexturedMaterials_CPU.h"
#include "TexturedMaterials_Vulkan.h"
#include "CommandLine.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

using LiteImage::Image2D;
using LiteImage::Sampler;
using LiteMath::float2;
using LiteMath::float4;

namespace {

// Textures of every address mode, half nearest, half bilinear; bump maps a quarter the size.
void Fill(TexturedMaterials& m, int textures, uint32_t side)
{
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  m.m_albedo.clear();
  m.m_bumps.clear();
  for (int t = 0; t < textures; ++t)
  {
    Sampler s;
    s.addressU = s.addressV = Sampler::AddressMode(t % 4);
    s.filter = t % 2 ? Sampler::Filter::LINEAR : Sampler::Filter::NEAREST;
    Image2D<float4> img(side, side);
    for (auto& texel : img.vector()) texel = float4(u(rng), u(rng), u(rng), 1.0f);
    m.m_albedo.emplace_back(std::move(img), s);
    Image2D<float> bump(side / 4, side / 4);
    for (auto& texel : bump.vector()) texel = u(rng);
    m.m_bumps.emplace_back(std::move(bump), s);
  }
}

}  // namespace

int main(int argc, char** argv)
{
  int n = 1 << 20, textures = 16;
  uint32_t side = 512;
  crossrt::CommandLine app("bench_textures", "Samples arrays of textures from buffers against the GPU samplers, and prints ratios.");
  app.add_option("N", n, "samples")->check(crossrt::Positive());
  app.add_option("TEXTURES", textures, "textures in the array")->check(crossrt::Positive());
  app.add_option("SIDE", side, "each texture's width and height")->check(crossrt::Positive());
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  const int repeats = 5;

  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.5f, 1.5f);
  std::vector<uint32_t> ids(n);
  std::vector<float2> uvs(n);
  for (int i = 0; i < n; ++i)
  {
    ids[i] = uint32_t(rng() % uint32_t(textures));
    uvs[i] = float2(u(rng), u(rng));
  }
  std::vector<float4> colors(n), texels(n), reference(n);
  std::vector<float> heights(n), referenceHeights(n);

  std::printf("Arrays of textures: %d hits, %d textures of %u x %u float4 (+ %d bump maps of %u x %u float)\n\n", n, textures, side, side,
              textures, side / 4, side / 4);
  std::printf("| implementation | sampling | ms | hits/s | vs original | GPU ms | max |diff| from the original |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  auto row = [&](const char* impl, const char* how, double ms, double baseMs, double gpuMs) {
    float diff = 0.0f;
    for (int i = 0; i < n; ++i)
    {
      const float4 d = colors[i] - reference[i];
      diff = std::max({diff, std::fabs(d.x), std::fabs(d.y), std::fabs(d.z), std::fabs(d.w), std::fabs(heights[i] - referenceHeights[i])});
    }
    char gpu[32] = "";
    if (gpuMs > 0.0) std::snprintf(gpu, sizeof gpu, "%.2f", gpuMs);
    std::printf("| %s | %s | %.2f | %.3g | %.2fx | %s | %.3g |\n", impl, how, ms, n / (ms * 1e-3), baseMs / ms, gpu, diff);
  };

  TexturedMaterials original;
  Fill(original, textures, side);
  const double baseMs = MedianMs(repeats, [&] { original.Shade(n, ids.data(), uvs.data(), reference.data(), referenceHeights.data(), texels.data()); });
  colors = reference;
  heights = referenceHeights;
  row("original (1 core)", "LiteImage", baseMs, baseMs, 0.0);

  auto cpu = CreateTexturedMaterials_CPU();
  Fill(*cpu, textures, side);
  const double cpuMs = MedianMs(repeats, [&] { cpu->Shade(n, ids.data(), uvs.data(), colors.data(), heights.data(), texels.data()); });
  row("_CPU (all cores)", "LiteImage", cpuMs, baseMs, 0.0);

  try
  {
    auto ctx = crossrt::VulkanContext::CreateDefault();
    auto gpu = std::make_shared<TexturedMaterials_Vulkan>(ctx);
    Fill(*gpu, textures, side);
    for (bool hardware : {false, true})
    {
      if (hardware && !ctx->hasTextureArrays)
      {
        std::printf("| _Vulkan (%s) | GPU samplers | device has no descriptor indexing | | | | |\n", ctx->DeviceName().c_str());
        continue;
      }
      gpu->UseTextureHardware(hardware);
      float t[4] = {};
      const double ms = MedianMs(repeats, [&] { gpu->Shade(n, ids.data(), uvs.data(), colors.data(), heights.data(), texels.data()); });
      gpu->GetExecutionTime("Shade", t);  // the last run's
      const std::string impl = "_Vulkan (" + ctx->DeviceName() + ")";
      row(impl.c_str(), hardware ? "GPU samplers" : "buffers, as LiteImage", ms, baseMs, t[0]);
    }
  }
  catch (const crossrt::Error& e)
  {
    std::printf("| _Vulkan | | %s | | | | |\n", e.what());
  }
  return 0;
}
