// path_tracer: renders a glTF 2.0 or OBJ scene with litept's PathTracer, as written (one thread),
// translated for all CPU cores (PathTracer_CPU; PathTracer_ISPC, one path a SIMD lane, where ISPC
// was found) or for Vulkan (PathTracer_Vulkan, megakernel or
// wavefront, at virtual level 1, 2 or 3), progressively in passes of bounded size, with a progress
// bar on stderr. Writes linear EXR or sRGB PNG; --compare prints the PSNR (8-bit sRGB) and relative
// MSE (linear) against a reference image, such as one from scripts/cycles-reference.py.
#include "ImageMetrics.h"
#include "PathTracer.h"
#include "PathTracer_CPU.h"
#ifdef CROSSRT_LITEPT_ISPC
#include "PathTracer_ISPC.h"
#endif
#include "PathTracer_Vulkan.h"
#include "PathTracer_VulkanLevel1.h"
#include "PathTracer_VulkanLevel3.h"
#include "SceneLoader.h"

#include "CommandLine.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using LiteMath::float4;

namespace {

struct Options
{
  std::string scene, device = "cpu", mode = "megakernel", accel = "embree", env, compare;
  std::vector<std::string> outs;  // one image per --out
  uint32_t width = 256, height = 256, spp = 64, passSpp = 4, seed = 0;
  int depth = 8, virtualLevel = 2;
  float envStrength = 1.0f;
};

template <class Generated>
std::shared_ptr<PathTracer> VulkanTracer(std::shared_ptr<crossrt::VulkanContext> ctx, crossrt::ExecutionMode mode)
{
  auto tracer = std::make_shared<Generated>(ctx);
  tracer->SetExecutionMode(mode);
  return tracer;
}

[[noreturn]] void Usage(const std::string& problem)
{
  std::fprintf(stderr, "path_tracer: error: %s (see --help)\n", problem.c_str());
  std::exit(2);
}

uint32_t Positive(const std::string& flag, const std::string& text)
{
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || v <= 0 || v > (1 << 24))
    Usage(flag + " takes a positive integer, not '" + text + "'");
  return uint32_t(v);
}

Options Parse(int argc, char** argv)
{
  Options o;
  std::string size = "256x256";
  crossrt::CommandLine app("path_tracer",
                           "Path traces SCENE (.gltf, .glb or .obj) with next-event estimation and multiple importance sampling.");
  app.add_option("SCENE", o.scene, "the scene: .gltf, .glb or .obj")->required();
  app.add_option("--size", size, "image size, WxH");
  app.add_option("--spp", o.spp, "samples per pixel")->check(crossrt::Positive());
  app.add_option("--depth", o.depth, "bounces, as Cycles counts them (0 is direct light only)")->check(CLI::Range(0, 64));
  app.add_option("--device", o.device,
                 "original: the class as written, one thread; cpu: PathTracer_CPU, all cores; ispc: PathTracer_ISPC, all\n"
                 "cores, one path a SIMD lane (where ISPC was found; CrossRT's BVHs); vulkan: PathTracer_Vulkan on the\n"
                 "default Vulkan device")
      ->check(CLI::IsMember({"original", "cpu", "ispc", "vulkan"}));
  app.add_option("--mode", o.mode, "PathTracer_Vulkan's execution mode")->check(CLI::IsMember({"megakernel", "wavefront"}));
  app.add_option("--virtual-level", o.virtualLevel,
                 "how the GPU reaches materials and lights (paper 3.9): 1, one array of equal slots\n"
                 "(PathTracer_VulkanLevel1); 2, a buffer per class (PathTracer_Vulkan); 3, as 2 plus callable shaders\n"
                 "where the device has ray tracing pipelines (PathTracer_VulkanLevel3)");
  app.add_option("--accel", o.accel, "the CPU devices' ray tracing: Embree or CrossRT's BVHs; ispc and vulkan use sah (or lbvh)")
      ->check(CLI::IsMember({"embree", "sah", "lbvh"}));
  app.add_option("--env", o.env, "an equirectangular environment map (linear EXR, Blender's orientation), times --env-strength");
  app.add_option("--env-strength", o.envStrength, "the environment map's strength");
  app.add_option("--seed", o.seed, "the random sequence (a pixel's samples depend only on pixel, sample index and seed)");
  app.add_option("--pass-spp", o.passSpp, "samples per pass: memory stays the same whatever --spp is (1 for megakernels on llvmpipe)")
      ->check(crossrt::Positive());
  app.add_option("--compare", o.compare, "prints PSNR (8-bit sRGB) and relative MSE (linear) of the image against this reference");
  app.add_option("--out", o.outs, ".exr: linear radiance; .png: sRGB, clamped (several --out: the same image to each)")->required();
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) std::exit(status);
  const size_t x = size.find('x');
  if (x == std::string::npos) Usage("--size takes WxH, not '" + size + "'");
  o.width = Positive("--size", size.substr(0, x));
  o.height = Positive("--size", size.substr(x + 1));
  if (o.virtualLevel < 1 || o.virtualLevel > 3) Usage("--virtual-level is 1, 2 or 3, not '" + std::to_string(o.virtualLevel) + "'");
  for (const std::string& out : o.outs)
  {
    const std::string ext = out.size() > 4 ? out.substr(out.size() - 4) : "";
    if (ext != ".exr" && ext != ".png") Usage("--out must end in .exr or .png, not '" + out + "'");
  }
  return o;
}

// The --compare image, read (and checked against --size) before rendering, so that a wrong one costs
// no render.
LiteImage::Image2D<float4> LoadReference(const std::string& refPath, uint32_t width, uint32_t height)
{
  LiteImage::Image2D<float4> ref;
  if (!LiteImage::LoadImage(refPath.c_str(), ref))
    throw std::runtime_error(refPath + ": error: the reference image could not be read");
  if (ref.width() != width || ref.height() != height)
    throw std::runtime_error(refPath + ": error: the reference is " + std::to_string(ref.width()) + "x" + std::to_string(ref.height()) +
                             ", the image " + std::to_string(width) + "x" + std::to_string(height));
  return ref;
}

}  // namespace

int main(int argc, char** argv)
{
  Options o = Parse(argc, argv);
  try
  {
    LiteImage::Image2D<float4> reference;
    if (!o.compare.empty())
      reference = LoadReference(o.compare, o.width, o.height);
    PathScene scene = LoadScene(o.scene);
    if (!o.env.empty())
      LoadEnvironment(scene, o.env, o.envStrength);
    ApplySceneDefaults(scene);
    for (const std::string& note : scene.notes)
      std::fprintf(stderr, "%s\n", note.c_str());

    std::shared_ptr<PathTracer> tracer;
    std::string accel = o.accel;
    if (o.device == "original")
      tracer = std::make_shared<PathTracer>();
    else if (o.device == "cpu")
      tracer = CreatePathTracer_CPU();
    else if (o.device == "ispc")
    {
#ifdef CROSSRT_LITEPT_ISPC
      tracer = CreatePathTracer_ISPC();
      if (accel == "embree")
        accel = "sah";  // its kernels run BVHScene's traversal, composed in
#else
      throw std::runtime_error("--device ispc: this build found no ISPC compiler (see the README: installing ISPC)");
#endif
    }
    else
    {
      auto ctx = crossrt::VulkanContext::CreateDefault();
      const auto mode = o.mode == "megakernel" ? crossrt::ExecutionMode::Megakernel : crossrt::ExecutionMode::Wavefront;
      // The same class translated at three virtual levels: three generated classes.
      tracer = o.virtualLevel == 1   ? VulkanTracer<PathTracer_VulkanLevel1>(ctx, mode)
               : o.virtualLevel == 3 ? VulkanTracer<PathTracer_VulkanLevel3>(ctx, mode)
                                     : VulkanTracer<PathTracer_Vulkan>(ctx, mode);
      std::fprintf(stderr, "device: %s, virtual level %d\n", ctx->DeviceName().c_str(), o.virtualLevel);
      if (ctx->loopIterationLimit != 0 && mode == crossrt::ExecutionMode::Megakernel && o.passSpp > 1)
      {
        // A megakernel pass runs all its samples' bounces and traversals in one invocation's loops.
        std::fprintf(stderr, "note: this device ends a shader's loops after %u iterations in all (llvmpipe), which a megakernel pass of "
                             "%u spp may reach: passes of 1 spp here\n", ctx->loopIterationLimit, o.passSpp);
        o.passSpp = 1;
      }
      accel = "sah";  // the GPU runs BVHScene's traversal
    }
    tracer->SetScene(scene, MakeSceneRT(accel.c_str()));
    tracer->SetImageAspect(float(o.width) / float(o.height));
    tracer->SetMaxDepth(o.depth);
    tracer->SetSeed(o.seed);
    tracer->CommitDeviceData();

    const size_t pixels = size_t(o.width) * o.height;
    std::vector<float4> pass(pixels), sum(pixels, float4(0.0f));
    const auto start = std::chrono::steady_clock::now();
    for (uint32_t done = 0; done < o.spp;)
    {
      const uint32_t n = std::min(o.passSpp, o.spp - done);
      tracer->RenderPass(o.width, o.height, done, int(n), pass.data());
      for (size_t i = 0; i < pixels; ++i)
        sum[i] += pass[i];
      done += n;
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const int bar = int(40.0 * done / o.spp);
      std::fprintf(stderr, "\r[%s%s] %u/%u spp, %.2f Mpaths/s, %.0f s left ", std::string(size_t(bar), '#').c_str(),
                   std::string(size_t(40 - bar), '.').c_str(), done, o.spp, double(pixels) * done / s * 1e-6, s / done * (o.spp - done));
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "\n");

    LiteImage::Image2D<float4> image(o.width, o.height);
    size_t bad = 0;
    for (size_t i = 0; i < pixels; ++i)
    {
      float4 v = sum[i] * (1.0f / float(o.spp));
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        ++bad, v = float4(0.0f);
      image.vector()[i] = float4(v.x, v.y, v.z, 1.0f);
    }
    for (const std::string& out : o.outs)
    {
      bool saved;
      if (out.substr(out.size() - 4) == ".png")
      {
        LiteImage::Image2D<uint32_t> png(o.width, o.height);
        for (size_t i = 0; i < pixels; ++i)
        {
          const float4 v = image.vector()[i];
          png.vector()[i] = litept::Srgb8(v.x) | litept::Srgb8(v.y) << 8 | litept::Srgb8(v.z) << 16 | 255u << 24;
        }
        saved = LiteImage::SaveImage(out.c_str(), png);
      }
      else
        saved = LiteImage::SaveImage(out.c_str(), image);
      if (!saved)
        throw std::runtime_error(out + ": error: could not write the image");
    }
    std::string written;
    for (const std::string& out : o.outs)
      written += (written.empty() ? "" : " and ") + out;
    std::printf("path_tracer: %s, %ux%u, %u spp, depth %d, %s%s: %.3f s (%.2f Mpaths/s); wrote %s\n", o.scene.c_str(), o.width, o.height, o.spp,
                o.depth, o.device.c_str(), o.device == "vulkan" ? (", " + o.mode).c_str() : "", seconds, double(pixels) * o.spp / seconds * 1e-6,
                written.c_str());
    if (bad > 0)
      throw std::runtime_error(std::to_string(bad) + " pixels were NaN or infinite (written as black)");
    if (!o.compare.empty())
    {
      const litept::ImageError e = litept::CompareImages(image.vector(), reference.vector());
      std::printf("compare: against %s: PSNR %.2f dB (8-bit sRGB), relMSE %.5f (linear)\n", o.compare.c_str(), e.psnr8, e.relMse);
    }
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "path_tracer: %s\n", e.what());
    return 1;
  }
  return 0;
}
