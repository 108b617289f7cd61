// Bloom on an image with the original class, Bloom_CPU and Bloom_Vulkan; prints a table of
// times and the largest difference, and writes the Vulkan result.
//   bloom [input image] [output image]
// Without an input (or with "") it renders its own HDR test scene (lights over a dark gradient).
#include "Bloom.h"
#include "Bloom_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "Bloom_ISPC.h"
#endif
#include "Bloom_Vulkan.h"
#include "Image2D.h"

#include "CommandLine.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

using namespace LiteMath;

static LiteImage::Image2D<float4> RenderTestScene(int w, int h)
{
  LiteImage::Image2D<float4> img(w, h);
  const float2 lights[4] = {{0.2f, 0.3f}, {0.7f, 0.25f}, {0.5f, 0.7f}, {0.85f, 0.8f}};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      const float u = (x + 0.5f) / w, v = (y + 0.5f) / h;
      float4 c(0.05f + 0.1f * v, 0.05f + 0.05f * v, 0.15f, 1.0f);
      if (((x / 32) + (y / 32)) % 2 == 0) c = c * 1.5f;
      for (const float2& l : lights)
      {
        const float d = length(float2(u, v) - l);
        if (d < 0.03f) c = float4(4.0f, 3.5f, 2.5f, 1.0f);
      }
      img.set(x, y, c);
    }
  return img;
}

int main(int argc, char** argv)
{
  std::string inPath, outPath = "bloom.png";
  crossrt::CommandLine app("bloom",
                           "Bloom of INPUT_IMAGE (\"\" or none: a built-in scene) by the original class, Bloom_CPU, Bloom_ISPC\n"
                           "(where built) and Bloom_Vulkan; writes OUTPUT.png and a table of times. Exits non-zero when they differ.");
  app.add_option("INPUT_IMAGE", inPath, "the image to filter (\"\": the built-in scene)");
  app.add_option("OUTPUT.png", outPath, "the filtered image");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  LiteImage::Image2D<float4> input;
  const bool photo = !inPath.empty();  // "" asks for the built-in scene
  if (photo)
  {
    if (!LiteImage::LoadImage(inPath.c_str(), input)) return 1;
  }
  else
    input = RenderTestScene(512, 512);
  const int w = int(input.width()), h = int(input.height());

  struct Run { const char* name; std::shared_ptr<Bloom> impl; std::vector<float4> out; double ms = 0.0; };
  std::vector<Run> runs;
  runs.push_back({"original (1 thread)", std::make_shared<Bloom>(w, h, 12, 5.0f), {}});
  runs.push_back({"Bloom_CPU (all cores)", CreateBloom_CPU(w, h, 12, 5.0f), {}});
#ifdef CROSSRT_HAS_ISPC
  runs.push_back({"Bloom_ISPC", CreateBloom_ISPC(w, h, 12, 5.0f), {}});
#endif
  try
  {
    runs.push_back({"Bloom_Vulkan", CreateBloom_Vulkan(w, h, 12, 5.0f), {}});
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "bloom: Vulkan is not available, skipping Bloom_Vulkan: %s\n", e.what());
  }
  const int repeats = 5;
  for (Run& r : runs)
  {
    if (photo) r.impl->m_threshold = 0.8f;  // photos are low dynamic range
    r.out.resize(size_t(w) * h);
    r.impl->CommitDeviceData();
    r.impl->Run(w, h, input.data(), r.out.data());  // warm-up
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < repeats; ++i) r.impl->Run(w, h, input.data(), r.out.data());
    r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / repeats;
  }

  std::printf("bloom on %dx%d, radius 12\n\n| %-22s | %10s | %8s | %14s |\n|%s|\n", w, h, "implementation", "ms/run", "speedup", "max |diff|", std::string(65, '-').c_str());
  float worst = 0.0f;
  for (Run& r : runs)
  {
    float diff = 0.0f;  // a NaN stays (std::max and hmax would drop it, and the check below would pass)
    for (size_t i = 0; i < r.out.size(); ++i)
      for (int c = 0; c < 4; ++c)
        if (const float d = std::fabs(r.out[i][c] - runs[0].out[i][c]); std::isnan(d) || d > diff) diff = d;
    if (std::isnan(diff) || diff > worst) worst = diff;
    std::printf("| %-22s | %10.2f | %7.2fx | %14.3g |\n", r.name, r.ms, runs[0].ms / r.ms, diff);
  }
  LiteImage::Image2D<float4> result(w, h, runs.back().out.data());
  if (!LiteImage::SaveImage(outPath.c_str(), result)) return 1;
  std::printf("\nwrote %s (from %s)\n", outPath.c_str(), runs.back().name);
  return worst < 1e-4f ? 0 : 1;
}
