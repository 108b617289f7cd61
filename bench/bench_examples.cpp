// Benchmark: each example class as the original single-threaded C++, as <Class>_CPU (OpenMP on
// all cores), as <Class>_ISPC (all cores, SIMD lanes on each; where ISPC is found) and as
// <Class>_Vulkan on the default device. Every figure comes from this one run; ratios are against
// the original, and _ISPC's also against _CPU. The CPU classes run in interleaved rounds after a
// warm-up round (7 for particles, 5 for the others), so that load on the machine slows them alike:
// each time is a median, each ratio the median of the rounds' ratios to the original. The GPU
// classes: medians of as many calls after a warm-up. The table goes to CSV too (default out/bench_examples.csv), which
// bench/plot_examples.py plots.
// SpherePaths runs on Vulkan in both execution modes: wavefront (one dispatch per kernel call) and
// megakernel (its thread loop as one shader). SphericalHarmonics (test/classes, kernel_slicer's
// spherical harmonics) reduces the nine elements of a member array over an image half as high as
// the bloom's is wide.
//   bench_examples [--load N] [particles] [bloom side] [paths side] [CSV]
// --load N runs N busy threads beside the measurement, and a warning row follows the table for
// each translated CPU class slower than the original (or _ISPC slower than _CPU).
#include "BenchSupport.h"
#include "Bloom.h"
#include "Bloom_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "Bloom_ISPC.h"
#include "Particles_ISPC.h"
#include "SpherePaths_ISPC.h"
#include "SphericalHarmonics_ISPC.h"
#endif
#include "Bloom_Vulkan.h"
#include "Particles.h"
#include "Particles_CPU.h"
#include "Particles_Vulkan.h"
#include "SpherePaths.h"
#include "SpherePaths_CPU.h"
#include "SpherePaths_Vulkan.h"
#include "SphericalHarmonics.h"
#include "SphericalHarmonics_CPU.h"
#include "SphericalHarmonics_Vulkan.h"
#include "CommandLine.h"

#include <cstdio>
#include <filesystem>
#include <functional>
#include <fstream>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

using LiteMath::float4;

namespace {

std::ofstream g_csv;  // example,implementation,ms_per_call,speedup_vs_original,gpu_ms_per_call

std::vector<std::string> g_slower;  // the translated CPU classes slower than they should be, for the warning rows

// One implementation of an example: its name, one call, and for a GPU class its timestamp-measured
// kernel time of the last call.
struct Impl
{
  std::string name;
  std::function<void()> call;
  std::function<double()> gpuMs;  // empty on the CPU
};

void Row(const char* example, const std::string& impl, double ms, double speedup, double gpuMs)
{
  char gpu[32] = "";
  if (gpuMs > 0.0) std::snprintf(gpu, sizeof gpu, "%.2f", gpuMs);
  std::printf("| %-10s | %-18s | %10.2f | %8.2fx | %12s |\n", example, impl.c_str(), ms, speedup, gpu);
  g_csv << example << "," << impl << "," << ms << "," << speedup << "," << gpuMs << "\n";
}

// The CPU implementations (the original first) in `rounds` interleaved rounds, so that load on the
// machine slows them alike: each ratio is the median of the rounds' ratios to the original. Then
// each GPU implementation, median of `rounds` calls after a warm-up, its ratio one of medians.
void Measure(const char* example, const std::vector<Impl>& impls, int rounds)
{
  std::vector<std::function<void()>> cpuCalls;
  std::vector<const Impl*> cpu;
  for (auto& impl : impls)
    if (!impl.gpuMs) cpuCalls.push_back(impl.call), cpu.push_back(&impl);
  const auto ms = InterleavedMs(cpuCalls, rounds);
  size_t cpuClass = cpu.size(), ispcClass = cpu.size();
  for (size_t i = 0; i < cpu.size(); ++i)
  {
    const double speedup = PairedRatio(ms[0], ms[i]);
    Row(example, cpu[i]->name, MedianOf(ms[i]), speedup, 0.0);
    if (i > 0 && speedup < 1.0)
      g_slower.push_back(cpu[i]->name + " takes " + std::to_string(1.0 / speedup).substr(0, 4) + "x the time of the original " + example);
    if (cpu[i]->name.find("_CPU") != std::string::npos) cpuClass = i;
    if (cpu[i]->name.find("_ISPC") != std::string::npos) ispcClass = i;
  }
  if (cpuClass < cpu.size() && ispcClass < cpu.size())
  {
    const double ispcSpeedup = PairedRatio(ms[cpuClass], ms[ispcClass]);
    std::printf("| %-10s | %-18s | %10s | %8.2fx | %12s |\n", example, "_ISPC vs _CPU", "", ispcSpeedup, "");
    if (ispcSpeedup < 1.0)
      g_slower.push_back(std::string(example) + ": _ISPC takes " + std::to_string(1.0 / ispcSpeedup).substr(0, 4) + "x the time of _CPU");
  }
  const double originalMs = MedianOf(ms[0]);
  double wavefrontMs = 0.0;
  for (auto& impl : impls)
  {
    if (!impl.gpuMs) continue;
    const double wall = MedianMs(rounds, impl.call);
    Row(example, impl.name, wall, originalMs / wall, impl.gpuMs());
    if (impl.name == "Vulkan wavefront") wavefrontMs = wall;
    if (impl.name == "Vulkan megakernel" && wavefrontMs > 0.0)
      std::printf("| %-10s | %-18s | %10s | %8.2fx | %12s |\n", example, "mega vs wavefront", "", wavefrontMs / wall, "");
  }
}

}  // namespace

int main(int argc, char** argv)
{
  int load = 0, particles = 1 << 20, side = 1024, pathSide = 256;
  std::string csvPath = "out/bench_examples.csv";
  crossrt::CommandLine app("bench_examples",
                           "Times the examples as written, as _CPU, _ISPC and _Vulkan, and prints ratios; the table goes to CSV too\n"
                           "(bench/plot_examples.py plots it).");
  app.add_option("PARTICLES", particles, "particles")->check(crossrt::Positive());
  app.add_option("IMAGE_SIDE", side, "the bloom image's side")->check(crossrt::Positive());
  app.add_option("PATH_SIDE", pathSide, "the path traced image's side")->check(crossrt::Positive());
  app.add_option("CSV", csvPath, "the table's CSV file");
  app.add_option("--load", load, "busy threads beside every measurement (a user's machine is never quiet)")->check(CLI::Range(0, 256));
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  constexpr int pathSamples = 8;
  if (std::filesystem::path(csvPath).has_parent_path()) std::filesystem::create_directories(std::filesystem::path(csvPath).parent_path());
  g_csv.open(csvPath);
  if (!g_csv)
  {
    std::fprintf(stderr, "bench_examples: cannot write %s\n", csvPath.c_str());
    return 1;
  }
  g_csv << "example,implementation,ms_per_call,speedup_vs_original,gpu_ms_per_call\n";
#ifndef CROSSRT_HAS_ISPC
  std::printf("no ISPC compiler was found at configure time: the _ISPC rows are left out\n");
#endif
  std::shared_ptr<crossrt::VulkanContext> ctx;
  try { ctx = crossrt::VulkanContext::CreateDefault(); }
  catch (const std::exception& e) { std::fprintf(stderr, "no Vulkan device, the _Vulkan rows are skipped: %s\n", e.what()); }

  const BusyThreads busy(load);
  std::printf("CPU: %s, %u threads; ISPC target: %s (%s); Vulkan device: %s; load: %d busy threads beside the measurement\n\n", CpuModel().c_str(),
              std::thread::hardware_concurrency(), crossrt::IspcTargetInUse().c_str(), IspcLanes(), ctx ? ctx->DeviceName().c_str() : "none", busy.Count());
  std::printf("| %-10s | %-18s | %10s | %9s | %12s |\n|%s|\n", "example", "implementation", "ms/call", "vs orig", "GPU ms/call", std::string(73, '-').c_str());

  {  // particles: two 1D kernels, one with 4 member reductions
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<float4> pos0(particles), vel0(particles);
    for (int i = 0; i < particles; ++i) { pos0[i] = float4(u(rng), 5.0f + u(rng), u(rng), 0.0f); vel0[i] = float4(u(rng), u(rng), u(rng), 0.0f); }
    std::vector<std::pair<std::string, std::shared_ptr<Particles>>> classes = {{"original", std::make_shared<Particles>()}, {"Particles_CPU", CreateParticles_CPU()}};
#ifdef CROSSRT_HAS_ISPC
    classes.push_back({"Particles_ISPC", CreateParticles_ISPC()});
#endif
    if (ctx) classes.push_back({"Particles_Vulkan", CreateParticles_Vulkan(ctx)});
    // Each steps its own copy of the particles.
    std::vector<std::vector<float4>> pos(classes.size(), pos0), vel(classes.size(), vel0);
    std::vector<Impl> impls;
    for (size_t c = 0; c < classes.size(); ++c)
    {
      auto p = classes[c].second;
      p->CommitDeviceData();
      impls.push_back({classes[c].first, [p, &pos, &vel, c, particles] { p->Step(particles, 0.001f, pos[c].data(), vel[c].data()); }, nullptr});
      if (classes[c].first == "Particles_Vulkan") impls.back().gpuMs = [p] { float t[4]; p->GetExecutionTime("Step", t); return double(t[0]); };
    }
    Measure("particles", impls, 7);
  }
  {  // bloom: three 2D kernels, a 25-tap separable blur
    std::vector<float4> in(size_t(side) * side), out(in.size());
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x) in[size_t(y) * side + x] = float4(float(x % 64) / 16.0f, float(y % 32) / 8.0f, 0.5f, 1.0f);
    std::vector<std::pair<std::string, std::shared_ptr<Bloom>>> classes = {{"original", std::make_shared<Bloom>(side, side, 12, 5.0f)}, {"Bloom_CPU", CreateBloom_CPU(side, side, 12, 5.0f)}};
#ifdef CROSSRT_HAS_ISPC
    classes.push_back({"Bloom_ISPC", CreateBloom_ISPC(side, side, 12, 5.0f)});
#endif
    if (ctx) classes.push_back({"Bloom_Vulkan", CreateBloom_Vulkan(ctx, side, side, 12, 5.0f)});
    std::vector<Impl> impls;
    for (auto& [name, b] : classes)
    {
      b->CommitDeviceData();
      impls.push_back({name, [b = b, &in, &out, side] { b->Run(side, side, in.data(), out.data()); }, nullptr});
      if (name == "Bloom_Vulkan") impls.back().gpuMs = [b = b] { float t[4]; b->GetExecutionTime("Run", t); return double(t[0]); };
    }
    Measure("bloom", impls, 5);
  }
  {  // paths: a 2D thread loop of four kernels, 8 samples x 4 bounces = 65 kernel calls per pixel
    const uint32_t w = uint32_t(pathSide);
    std::vector<float4> out(size_t(w) * w);
    std::vector<std::pair<std::string, std::shared_ptr<SpherePaths>>> classes = {{"original", std::make_shared<SpherePaths>()}, {"SpherePaths_CPU", CreateSpherePaths_CPU()}};
#ifdef CROSSRT_HAS_ISPC
    classes.push_back({"SpherePaths_ISPC", CreateSpherePaths_ISPC()});
#endif
    if (ctx)
    {
      auto wavefront = std::make_shared<SpherePaths_Vulkan>(ctx), megakernel = std::make_shared<SpherePaths_Vulkan>(ctx);
      wavefront->SetExecutionMode(crossrt::ExecutionMode::Wavefront);
      megakernel->SetExecutionMode(crossrt::ExecutionMode::Megakernel);
      classes.push_back({"Vulkan wavefront", wavefront});
      classes.push_back({"Vulkan megakernel", megakernel});
    }
    std::vector<Impl> impls;
    for (auto& [name, p] : classes)
    {
      p->CommitDeviceData();
      impls.push_back({name, [p = p, &out, w] { p->Render(w, w, pathSamples, out.data()); }, nullptr});
      if (name.rfind("Vulkan", 0) == 0) impls.back().gpuMs = [p = p] { float t[4]; p->GetExecutionTime("Render", t); return double(t[0]); };
    }
    Measure("paths", impls, 5);
  }
  {  // spharm: kernel_slicer's spherical harmonics, a 2D kernel reducing the nine elements of a member array
    const uint32_t w = uint32_t(side), h = uint32_t(side / 2);
    std::vector<uint32_t> texels(size_t(w) * h);
    for (size_t i = 0; i < texels.size(); ++i) texels[i] = uint32_t(i * 2654435761u) ^ uint32_t(i >> 3);
    std::vector<std::pair<std::string, std::shared_ptr<SphericalHarmonics>>> classes = {{"original", std::make_shared<SphericalHarmonics>()},
                                                                                         {"Harmonics_CPU", CreateSphericalHarmonics_CPU()}};
#ifdef CROSSRT_HAS_ISPC
    classes.push_back({"Harmonics_ISPC", CreateSphericalHarmonics_ISPC()});
#endif
    std::shared_ptr<SphericalHarmonics_Vulkan> vulkan = ctx ? std::make_shared<SphericalHarmonics_Vulkan>(ctx) : nullptr;
    if (vulkan) classes.push_back({"Harmonics_Vulkan", vulkan});
    std::vector<Impl> impls;
    for (auto& [name, sh] : classes)
    {
      sh->CommitDeviceData();
      impls.push_back({name, [sh = sh, &texels, w, h] { sh->Project(texels.data(), w, h); }, nullptr});
    }
    if (vulkan) impls.back().gpuMs = [vulkan] { float t[4]; vulkan->GetExecutionTime("Project", t); return double(t[0]); };
    Measure("spharm", impls, 5);
  }
  if (!g_slower.empty())
  {
    std::printf("\nWARNING: translated classes slower than they should be (load: %d busy threads):\n", busy.Count());
    for (auto& line : g_slower) std::printf("| WARNING | %s |\n", line.c_str());
  }
  std::printf("\nparticles: %d particles per step; bloom: %dx%d image, radius 12; paths: %dx%d pixels, %d paths per pixel, 4 bounces;\n"
              "spharm: a %dx%d environment map onto 9 coefficients.\n", particles, side, side, pathSide, pathSide, pathSamples, side, side / 2);
  std::printf("ms/call: medians of interleaved rounds (CPU classes); vs orig: medians of the rounds' ratios (GPU: ratios of medians).\n");
  std::printf("_Vulkan ms/call includes copying the arguments in and out; 'GPU ms' is the timestamp-measured kernel time.\n");
  std::printf("table: %s (plot it: bench/plot_examples.py %s out/bench_examples.png)\n", csvPath.c_str(), csvPath.c_str());
  return 0;
}
