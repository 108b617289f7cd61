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

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using LiteMath::float4;

namespace {

const char* kUsage =
    "usage: path_tracer SCENE [--size WxH] [--spp N] [--depth D] [--device original|cpu|ispc|vulkan]\n"
    "                   [--mode megakernel|wavefront] [--virtual-level 1|2|3] [--accel embree|sah|lbvh]\n"
    "                   [--env FILE.exr] [--env-strength F]\n"
    "                   [--seed S] [--pass-spp K] [--compare REF.exr] --out FILE.exr|FILE.png [--out ...]\n"
    "  Path traces SCENE (.gltf, .glb or .obj) with next-event estimation and multiple importance sampling.\n"
    "  --size      image size (default 256x256)            --spp     samples per pixel (default 64)\n"
    "  --depth     bounces, as Cycles counts them (default 8; 0 is direct light only)\n"
    "  --device    original: the class as written, one thread; cpu: PathTracer_CPU, all cores (default);\n"
    "              ispc: PathTracer_ISPC, all cores, one path a SIMD lane (where ISPC was found; CrossRT's BVHs);\n"
    "              vulkan: PathTracer_Vulkan on the default Vulkan device\n"
    "  --mode      PathTracer_Vulkan's execution mode (default megakernel)\n"
    "  --virtual-level  how the GPU reaches materials and lights (paper 3.9): 1, one array of equal slots\n"
    "              (PathTracer_VulkanLevel1); 2, a buffer per class (PathTracer_Vulkan, default); 3, as 2 plus\n"
    "              callable shaders where the device has ray tracing pipelines (PathTracer_VulkanLevel3)\n"
    "  --accel     the CPU devices' ray tracing: Embree (default) or CrossRT's BVHs; ispc and vulkan use sah (or lbvh)\n"
    "  --env       an equirectangular environment map (linear EXR, Blender's orientation), times --env-strength\n"
    "  --seed      the random sequence (a pixel's samples depend only on pixel, sample index and seed)\n"
    "  --pass-spp  samples per pass (default 4): memory stays the same whatever --spp is (1 for megakernels on llvmpipe)\n"
    "  --compare   prints PSNR (8-bit sRGB) and relative MSE (linear) of the image against REF\n"
    "  --out       .exr: linear radiance; .png: sRGB, clamped (several --out: the same image to each)\n";

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
  std::fprintf(stderr, "path_tracer: error: %s\n%s", problem.c_str(), kUsage);
  std::exit(2);
}

uint32_t Positive(const std::string& flag, const char* text)
{
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (*end != '\0' || v <= 0 || v > (1 << 24))
    Usage(flag + " takes a positive integer, not '" + text + "'");
  return uint32_t(v);
}

Options Parse(int argc, char** argv)
{
  Options o;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h")
    {
      std::printf("%s", kUsage);
      std::exit(0);
    }
    const bool takesValue = a.rfind("--", 0) == 0;
    if (takesValue && i + 1 >= argc)
      Usage(a + " needs a value");
    if (a == "--size")
    {
      const std::string v = argv[++i];
      const size_t x = v.find('x');
      if (x == std::string::npos)
        Usage("--size takes WxH, not '" + v + "'");
      o.width = Positive(a, v.substr(0, x).c_str());
      o.height = Positive(a, v.substr(x + 1).c_str());
    }
    else if (a == "--spp") o.spp = Positive(a, argv[++i]);
    else if (a == "--pass-spp") o.passSpp = Positive(a, argv[++i]);
    else if (a == "--seed") o.seed = uint32_t(std::strtoul(argv[++i], nullptr, 10));
    else if (a == "--depth")
    {
      o.depth = std::atoi(argv[++i]);
      if (o.depth < 0 || o.depth > 64)
        Usage("--depth takes 0 to 64");
    }
    else if (a == "--device") o.device = argv[++i];
    else if (a == "--mode") o.mode = argv[++i];
    else if (a == "--virtual-level")
    {
      const std::string v = argv[++i];
      if (v != "1" && v != "2" && v != "3")
        Usage("--virtual-level is 1, 2 or 3, not '" + v + "'");
      o.virtualLevel = std::stoi(v);
    }
    else if (a == "--accel") o.accel = argv[++i];
    else if (a == "--env") o.env = argv[++i];
    else if (a == "--env-strength") o.envStrength = float(std::atof(argv[++i]));
    else if (a == "--compare") o.compare = argv[++i];
    else if (a == "--out") o.outs.push_back(argv[++i]);
    else if (takesValue) Usage("unknown option " + a);
    else if (o.scene.empty()) o.scene = a;
    else Usage("more than one scene: '" + o.scene + "' and '" + a + "'");
  }
  if (o.scene.empty()) Usage("no scene given");
  if (o.outs.empty()) Usage("no --out file given");
  if (o.device != "original" && o.device != "cpu" && o.device != "ispc" && o.device != "vulkan")
    Usage("--device is original, cpu, ispc or vulkan, not '" + o.device + "'");
  if (o.mode != "megakernel" && o.mode != "wavefront") Usage("--mode is megakernel or wavefront, not '" + o.mode + "'");
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
