// Benchmark: litept's PathTracer on a glTF scene (the Cornell box by default), from one run:
//   1. the paper's Table 10 form: samples per second of the class as written (one thread),
//      PathTracer_CPU (all cores), PathTracer_Vulkan as a megakernel and as plain wavefront, and
//      PathTracer_ISPC (SIMD lanes, where ISPC was found) beside PathTracer_CPU over the same BVHScene,
//      in interleaved rounds (medians), with the ratio to the original, and a warning row for a
//      translated CPU class slower than the original or PathTracer_ISPC slower than its peer;
//   2. the paper's Table 11 form: PathTracer_Vulkan translated at virtual levels 1 (one array of
//      equal slots, PathTracer_VulkanLevel1), 2 (a buffer per class, PathTracer_Vulkan) and 3 (2 plus
//      callable shaders where the device has ray tracing pipelines, PathTracer_VulkanLevel3), both
//      modes, interleaved rounds;
//   3. the gain from specialisation: PathTracer_Vulkan with its virtual calls specialised to the
//      material and light classes the scene holds, and with every class's case: the time to make
//      the pipelines, the speed, and the megakernel's SPIR-V size once spirv-opt has folded the
//      constants as the driver does;
//   4. time to equal quality against Blender's Cycles on the same cores, with --reference REF.exr
//      (a converged image) and --cycles-log CSV (scripts/cycles-reference.py --time-log, its
//      renders at 1, 2, 4, ... spp): PathTracer_CPU renders the same spp, each from scratch; both
//      get PSNR and relative MSE against the reference, and the time each needs for 30 and 35 dB is
//      interpolated on log-time. Writes the curves to CSV for bench/plot_path_tracer.py.
#include "BenchSupport.h"
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
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using LiteMath::float4;

// The megakernel's SPIR-V, from the generated PathTracer_Vulkan_shaders.cpp.
extern const uint32_t PathTracer_RenderPass_Megakernel_spv[];
extern const size_t PathTracer_RenderPass_Megakernel_spvBytes;

namespace {

// The generated class as a user subclasses it: the classes its pipelines were made for.
class InspectedTracer : public PathTracer_Vulkan
{
public:
  using PathTracer_Vulkan::PathTracer_Vulkan;
  // Per (vector, class), whether the pipelines switch over it; then the CRT_SPECIALIZE members' values.
  std::vector<uint32_t> PipelineConstants() const { return crt_pipelineConstants; }
  static constexpr size_t kClassConstants = crt_classConstants;
};

struct Setup
{
  PathScene scene;
  uint32_t size = 128;
  int depth = 8;
};

void Prepare(PathTracer& t, const Setup& s, const char* accel)
{
  t.SetScene(s.scene, MakeSceneRT(accel));
  t.SetImageAspect(1.0f);
  t.SetMaxDepth(s.depth);
  t.SetSeed(1);
  t.CommitDeviceData();
}

// Samples per pass on the Vulkan device: 1 where the device ends a shader's loops after so many
// iterations in all (llvmpipe: VulkanContext::loopIterationLimit), which a megakernel pass of many
// samples would reach, losing paths; 16 elsewhere, as on the CPU.
int gVulkanPassSpp = 16;

bool OnVulkan(const PathTracer& t)
{
  return dynamic_cast<const PathTracer_Vulkan*>(&t) || dynamic_cast<const PathTracer_VulkanLevel1*>(&t) ||
         dynamic_cast<const PathTracer_VulkanLevel3*>(&t);
}

// The mean of `spp` samples per pixel, rendered from scratch.
std::vector<float4> Render(PathTracer& t, const Setup& s, int spp)
{
  std::vector<float4> pass(size_t(s.size) * s.size), sum(pass.size(), float4(0.0f));
  const int passSpp = OnVulkan(t) ? gVulkanPassSpp : 16;
  for (int done = 0; done < spp;)
  {
    const int n = std::min(passSpp, spp - done);
    t.RenderPass(s.size, s.size, uint32_t(done), n, pass.data());
    for (size_t i = 0; i < pass.size(); ++i)
      sum[i] += pass[i];
    done += n;
  }
  for (auto& v : sum)
    v = v * (1.0f / float(spp));
  return sum;
}

double Median(std::vector<double> v)
{
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The megakernel's SPIR-V size after spirv-opt sets the specialization constants as `constants`
// (the classes held, true or false, then the CRT_SPECIALIZE members' values) and optimises (what a
// driver does with the specialisation); 0 when spirv-opt is missing.
size_t SpecialisedSpirvBytes(const std::vector<uint32_t>& constants)
{
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const std::string in = (dir / "bench_path_tracer_megakernel.spv").string(), out = (dir / "bench_path_tracer_megakernel_opt.spv").string();
  std::ofstream(in, std::ios::binary).write(reinterpret_cast<const char*>(PathTracer_RenderPass_Megakernel_spv),
                                            std::streamsize(PathTracer_RenderPass_Megakernel_spvBytes));
  std::string values;
  for (size_t i = 0; i < constants.size(); ++i)
    values += (i ? " " : "") + std::to_string(crossrt::kClassConstantIdBase + i) + ":" +
              (i >= InspectedTracer::kClassConstants ? std::to_string(constants[i]) : constants[i] ? "true" : "false");
  const std::string cmd = "spirv-opt --set-spec-const-default-value \"" + values + "\" --freeze-spec-const -O " + in + " -o " + out + " 2>/dev/null";
  if (std::system(cmd.c_str()) != 0)
    return 0;
  std::ifstream f(out, std::ios::binary | std::ios::ate);
  return f ? size_t(f.tellg()) : 0;
}

struct Curve
{
  std::vector<double> seconds, psnr;
};

// Seconds to reach `db` on a curve of rising quality, interpolated on log-time; <0 if never reached.
double TimeTo(const Curve& c, double db)
{
  for (size_t i = 0; i < c.psnr.size(); ++i)
    if (c.psnr[i] >= db)
    {
      if (i == 0)
        return c.seconds[0];
      const double f = (db - c.psnr[i - 1]) / (c.psnr[i] - c.psnr[i - 1]);
      return std::exp(std::log(c.seconds[i - 1]) + f * (std::log(c.seconds[i]) - std::log(c.seconds[i - 1])));
    }
  return -1.0;
}

std::vector<float4> LoadExr(const std::string& path, uint32_t size)
{
  LiteImage::Image2D<float4> img;
  if (!LiteImage::LoadImage(path.c_str(), img))
    throw std::runtime_error(path + ": error: cannot read the image");
  if (img.width() != size || img.height() != size)
    throw std::runtime_error(path + ": error: the image is " + std::to_string(img.width()) + "x" + std::to_string(img.height()) +
                             ", the benchmark renders " + std::to_string(size) + "x" + std::to_string(size) + " (--size)");
  return img.vector();
}

}  // namespace

int main(int argc, char** argv)
{
  Setup s;
  std::string scenePath = CROSSRT_CORNELL_BOX, reference, cyclesLog, csvPath = "out/bench_path_tracer.csv";
  int rounds = 3, maxSpp = 1024;
  bool vulkan = true;
  crossrt::CommandLine app("bench_path_tracer",
                           "Prints the path tracer's samples per second per implementation and mode, the gain from specialising virtual\n"
                           "calls to the scene, and (with a converged reference and Cycles' time log) the time to 30 and 35 dB against Cycles.");
  app.add_option("SCENE", scenePath, "the scene (default: the build's Cornell box)");
  app.add_option("--size", s.size, "width and height in pixels")->check(CLI::Range(8, 1 << 14));
  app.add_option("--depth", s.depth, "bounces")->check(CLI::Range(0, 64));
  app.add_option("--rounds", rounds, "interleaved rounds")->check(crossrt::Positive());
  app.add_option("--max-spp", maxSpp, "samples per pixel at most, in the time-to-quality table")->check(crossrt::Positive());
  app.add_option("--reference", reference, "a converged reference image (EXR)");
  app.add_option("--cycles-log", cyclesLog, "Cycles' time log (CSV), beside --reference");
  app.add_option("--csv", csvPath, "the table's CSV file");
  app.add_flag("!--no-vulkan", vulkan, "leave out PathTracer_Vulkan");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  try
  {
    s.scene = LoadScene(scenePath);
    ApplySceneDefaults(s.scene);
    const double paths = double(s.size) * s.size;
    std::printf("bench_path_tracer: %s, %ux%u, depth %d, %d interleaved rounds\n", scenePath.c_str(), s.size, s.size, s.depth, rounds);
    std::printf("CPU: %s, %u threads; ISPC target: %s (%s)\n\n", CpuModel().c_str(), std::thread::hardware_concurrency(), crossrt::IspcTargetInUse().c_str(),
                IspcLanes());

    // ---- 1. Table 10: megakernel against wavefront
    PathTracer original;
    Prepare(original, s, "embree");
    auto cpu = CreatePathTracer_CPU();
    Prepare(*cpu, s, "embree");
    std::shared_ptr<InspectedTracer> gpu;
    std::shared_ptr<PathTracer_VulkanLevel1> gpuLevel1;
    std::shared_ptr<PathTracer_VulkanLevel3> gpuLevel3;
    if (vulkan)
    {
      try
      {
        auto ctx = crossrt::VulkanContext::CreateDefault();
        if (ctx->loopIterationLimit != 0)
          gVulkanPassSpp = 1;
        gpu = std::make_shared<InspectedTracer>(ctx);
        Prepare(*gpu, s, "sah");
        gpuLevel1 = std::make_shared<PathTracer_VulkanLevel1>(ctx);
        Prepare(*gpuLevel1, s, "sah");
        gpuLevel3 = std::make_shared<PathTracer_VulkanLevel3>(ctx);
        Prepare(*gpuLevel3, s, "sah");
      }
      catch (const crossrt::NoDeviceError& e)
      {
        std::printf("(no Vulkan device: %s; the Vulkan rows are left out)\n\n", e.what());
        gpu.reset();
      }
    }
    struct Row
    {
      std::string name, mode;
      PathTracer* tracer;
      int spp;
      std::function<void()> before;
      std::vector<double> seconds;
    };
    std::vector<Row> rows = {{"PathTracer (as written, 1 thread)", "-", &original, 1, [] {}, {}},
                             {"PathTracer_CPU (all cores)", "-", cpu.get(), 8, [] {}, {}}};
    if (gpu)
    {
      rows.push_back({"PathTracer_Vulkan", "megakernel", gpu.get(), 4, [&] { gpu->SetExecutionMode(crossrt::ExecutionMode::Megakernel); }, {}});
      rows.push_back({"PathTracer_Vulkan", "wavefront", gpu.get(), 4, [&] { gpu->SetExecutionMode(crossrt::ExecutionMode::Wavefront); }, {}});
      // First use: the pipelines of each mode are made before timing. The two modes trace the same
      // paths: images that differ mean one lost work (the loop limit above), and its times mean nothing.
      std::vector<float4> images[2];
      for (int m = 0; m < 2; ++m)
        rows[2 + size_t(m)].before(), images[m] = Render(*gpu, s, 4);
      size_t differ = 0;
      for (size_t i = 0; i < images[0].size(); ++i)
        differ += std::fabs(images[0][i].y - images[1][i].y) > 1e-4f * std::max(1.0f, std::fabs(images[1][i].y));
      if (differ > 0)
        std::printf("(warning: the megakernel's and the wavefront's images differ at %zu pixels: the Vulkan times below are not for the same work)\n\n",
                    differ);
    }
    // The ISPC class runs the thread loop in SIMD lanes with BVHScene's traversal composed in; the CPU
    // class over the same BVHScene is its like-for-like peer.
    auto cpuBvh = CreatePathTracer_CPU();
    Prepare(*cpuBvh, s, "sah");
    rows.push_back({"PathTracer_CPU (all cores, BVHScene)", "-", cpuBvh.get(), 8, [] {}, {}});
#ifdef CROSSRT_LITEPT_ISPC
    auto ispc = CreatePathTracer_ISPC();
    Prepare(*ispc, s, "sah");
    rows.push_back({"PathTracer_ISPC (all cores, BVHScene)", "-", ispc.get(), 8, [] {}, {}});
#endif
    // Three untimed calls first, as a program's first passes: by then PathTracer_ISPC has run its
    // thread loop both in SIMD lanes and as PathTracer_CPU does, and keeps the faster (crossrt::LaneChoice).
    for (int warm = 0; warm < 3; ++warm)
      for (auto& r : rows)
        r.before(), Render(*r.tracer, s, r.spp);
    for (int round = 0; round < rounds; ++round)
      for (auto& r : rows)
      {
        r.before();
        r.seconds.push_back(Seconds([&] { Render(*r.tracer, s, r.spp); }));
      }
    if (std::filesystem::path(csvPath).has_parent_path())
      std::filesystem::create_directories(std::filesystem::path(csvPath).parent_path());
    std::ofstream csv(csvPath);
    csv << "table,implementation,mode,spp,seconds,samples_per_s,mpaths_per_s,vs_original,psnr_db,relmse\n";
    std::printf("Table 10 form (%s): samples per pixel per second, medians of %d rounds\n\n", scenePath.c_str(), rounds);
    std::printf("| implementation | mode | spp per round | spp/s | Mpaths/s | vs original |\n|---|---|---|---|---|---|\n");
    const double originalRate = rows[0].spp / Median(rows[0].seconds);
    for (auto& r : rows)
    {
      const double rate = r.spp / Median(r.seconds);
      std::printf("| %s | %s | %d | %.2f | %.3f | %.2fx |\n", r.name.c_str(), r.mode.c_str(), r.spp, rate, rate * paths * 1e-6, rate / originalRate);
      csv << "throughput," << r.name << "," << r.mode << "," << r.spp << "," << Median(r.seconds) << "," << rate << "," << rate * paths * 1e-6 << ","
          << rate / originalRate << ",,\n";
    }
    // Warning rows: a translated CPU class slower than the original, or PathTracer_ISPC slower than
    // its like-for-like peer, PathTracer_CPU over BVHScene (no ISPC target may fall below it).
    std::vector<std::string> slower;
    double cpuOverBvhRate = 0.0;  // (its row comes before PathTracer_ISPC's)
    for (auto& r : rows)
    {
      const double rate = r.spp / Median(r.seconds);
      const bool translatedCpu = r.name.rfind("PathTracer_CPU", 0) == 0 || r.name.rfind("PathTracer_ISPC", 0) == 0;
      if (translatedCpu && rate < originalRate)
        slower.push_back(r.name + " at " + std::to_string(rate / originalRate).substr(0, 4) + "x the original's samples per second");
      if (r.name == "PathTracer_CPU (all cores, BVHScene)") cpuOverBvhRate = rate;
      if (r.name == "PathTracer_ISPC (all cores, BVHScene)" && rate < cpuOverBvhRate)
        slower.push_back(r.name + " at " + std::to_string(rate / cpuOverBvhRate).substr(0, 4) +
                         "x the samples per second of PathTracer_CPU (all cores, BVHScene)");
    }
    if (!slower.empty())
    {
      std::printf("\nWARNING: translated classes slower than they should be:\n");
      for (auto& line : slower) std::printf("| WARNING | %s |\n", line.c_str());
    }

    // ---- 2. Table 11: virtual levels
    if (gpu)
    {
      std::vector<Row> levels;
      for (const char* mode : {"megakernel", "wavefront"})
      {
        const auto m = std::string(mode) == "megakernel" ? crossrt::ExecutionMode::Megakernel : crossrt::ExecutionMode::Wavefront;
        levels.push_back({"1 (PathTracer_VulkanLevel1)", mode, gpuLevel1.get(), 4, [&, m] { gpuLevel1->SetExecutionMode(m); }, {}});
        levels.push_back({"2 (PathTracer_Vulkan)", mode, gpu.get(), 4, [&, m] { gpu->SetExecutionMode(m); }, {}});
        levels.push_back({"3 (PathTracer_VulkanLevel3)", mode, gpuLevel3.get(), 4, [&, m] { gpuLevel3->SetExecutionMode(m); }, {}});
      }
      for (auto& r : levels)  // the pipelines of each mode are made before timing
        r.before(), Render(*r.tracer, s, 1);
      for (int round = 0; round < rounds; ++round)
        for (auto& r : levels)
        {
          r.before();
          r.seconds.push_back(Seconds([&] { Render(*r.tracer, s, r.spp); }));
        }
      std::printf("\nTable 11 form: PathTracer_Vulkan translated at each virtual level, samples per pixel per second, medians of %d rounds\n\n",
                  rounds);
      std::printf("| virtual level | mode | spp/s | Mpaths/s | vs level 2 |\n|---|---|---|---|---|\n");
      for (size_t i = 0; i < levels.size(); ++i)
      {
        const Row& r = levels[i];
        const Row& sameModeLevel2 = levels[i - i % 3 + 1];  // each mode's rows are levels 1, 2, 3
        const double rate = r.spp / Median(r.seconds), level2 = sameModeLevel2.spp / Median(sameModeLevel2.seconds);
        std::printf("| %s | %s | %.2f | %.3f | %.2fx |\n", r.name.c_str(), r.mode.c_str(), rate, rate * paths * 1e-6, rate / level2);
        csv << "virtual_level," << r.name << "," << r.mode << "," << r.spp << "," << Median(r.seconds) << "," << rate << "," << rate * paths * 1e-6
            << "," << rate / level2 << ",,\n";
      }
      std::printf("(level 3 runs callable shaders only where the device has ray tracing pipelines, and only in wavefront mode:\n"
                  " kernel_Shade_Callables_Textures; a megakernel keeps level 2's switch)\n");
    }

    // ---- 3. specialisation to the scene's classes
    if (gpu)
    {
      gpu->SetExecutionMode(crossrt::ExecutionMode::Megakernel);
      std::printf("\nSpecialisation: PathTracer_Vulkan's megakernel, virtual calls switched over the scene's classes or over all\n\n");
      std::printf("| virtual calls | classes in the pipelines | pipelines made, s (CommitDeviceData and a first 1-spp pass) | spp/s | SPIR-V bytes (folded by spirv-opt) |\n|---|---|---|---|---|\n");
      for (bool specialise : {false, true})  // each remakes the pipelines
      {
        gpu->SpecializeVirtualCalls(specialise);
        // Some drivers (lavapipe) compile a pipeline's shaders at its first dispatch, unless their disk
        // cache has them: the first 1-spp pass counts as making the pipelines.
        const double make = Seconds([&] { gpu->CommitDeviceData(), Render(*gpu, s, 1); });
        std::vector<double> t;
        for (int round = 0; round < rounds; ++round)
          t.push_back(Seconds([&] { Render(*gpu, s, 4); }));
        const std::vector<uint32_t> constants = gpu->PipelineConstants();
        const auto classes = constants.begin() + std::ptrdiff_t(InspectedTracer::kClassConstants);
        const size_t count = size_t(std::count(constants.begin(), classes, uint32_t(VK_TRUE)));
        const size_t bytes = SpecialisedSpirvBytes(constants);
        std::printf("| %s | %zu of %zu | %.2f | %.2f | %zu |\n", specialise ? "specialised to the scene" : "every class", count, InspectedTracer::kClassConstants, make,
                    4.0 / Median(t), bytes);
        csv << "specialisation," << (specialise ? "specialised" : "all classes") << ",megakernel,4," << Median(t) << "," << 4.0 / Median(t) << ","
            << 4.0 / Median(t) * paths * 1e-6 << ",," << bytes << ",\n";
      }
      gpu->SpecializeVirtualCalls(true);
    }

    // ---- 4. time to equal quality against Cycles
    if (reference.empty() || cyclesLog.empty())
    {
      std::printf("\nTime to quality against Cycles: give --reference REF.exr (converged, another seed) and --cycles-log CSV\n"
                  "(blender -b --factory-startup --python scripts/cycles-reference.py -- SCENE --out C.exr --size %ux%u --depth %d\n"
                  " --threads 2 --seed 1 --spp %d --time-log C.csv)\n",
                  s.size, s.size, s.depth, maxSpp);
      return 0;
    }
    const std::vector<float4> ref = LoadExr(reference, s.size);
    Curve ours, cycles;
    std::ifstream log(cyclesLog);
    if (!log)
      throw std::runtime_error(cyclesLog + ": error: cannot read the Cycles time log");
    std::string line;
    std::getline(log, line);  // spp,seconds,path
    while (std::getline(log, line))
    {
      std::stringstream ls(line);
      std::string spp, sec, path;
      std::getline(ls, spp, ',');
      std::getline(ls, sec, ',');
      std::getline(ls, path);
      const litept::ImageError e = litept::CompareImages(LoadExr(path, s.size), ref);
      cycles.seconds.push_back(std::stod(sec));
      cycles.psnr.push_back(e.psnr8);
      csv << "quality,Cycles,-," << spp << "," << sec << ",,,," << e.psnr8 << "," << e.relMse << "\n";
    }
    for (int spp = 1; spp <= maxSpp; spp *= 2)
    {
      std::vector<float4> image;
      const double sec = Seconds([&] { image = Render(*cpu, s, spp); });
      const litept::ImageError e = litept::CompareImages(image, ref);
      ours.seconds.push_back(sec);
      ours.psnr.push_back(e.psnr8);
      csv << "quality,PathTracer_CPU,-," << spp << "," << sec << ",,,," << e.psnr8 << "," << e.relMse << "\n";
    }
    std::printf("\nTime to equal quality against %s (PSNR, 8-bit sRGB), both renderers on this machine's cores\n\n", reference.c_str());
    std::printf("| renderer | to 30 dB (s) | to 35 dB (s) | best PSNR (dB) |\n|---|---|---|---|\n");
    for (auto& [name, c] : {std::pair<const char*, Curve&>{"PathTracer_CPU", ours}, {"Cycles", cycles}})
    {
      auto show = [](double t) { return t < 0.0 ? std::string("not reached") : std::to_string(t); };
      std::printf("| %s | %s | %s | %.2f |\n", name, show(TimeTo(c, 30.0)).c_str(), show(TimeTo(c, 35.0)).c_str(),
                  c.psnr.empty() ? 0.0 : *std::max_element(c.psnr.begin(), c.psnr.end()));
    }
    std::printf("\nwrote %s (plot: bench/plot_path_tracer.py %s)\n", csvPath.c_str(), csvPath.c_str());
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "bench_path_tracer: %s\n", e.what());
    return 1;
  }
  return 0;
}
