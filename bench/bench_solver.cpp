// Benchmark: what "iterate until converged" costs when host code between kernel calls reads what
// the kernels wrote (issue 52). HeatDiffusion (test/conformance/cases/solver_loops.cpp) runs Jacobi
// steps until the largest change of a step is below a tolerance, at most 5,000 of them: Solve reads
// the residual after every step, SolveChecked(k) only every k steps. On Vulkan each read splits the
// recording (submit, wait, read the members back), so checking every step costs a round trip per
// step; checking every k steps, one per k. Each implementation runs as the original single-threaded
// C++, as _CPU (all cores), as _ISPC (where ISPC is found) and as _Vulkan on the default device, in
// interleaved rounds (the machine's noise spreads over all rows alike); each figure is the median.
// The table also goes to CSV (default out/bench_solver.csv), which bench/plot_solver.py plots.
//   bench_solver [SIDE (default 64)] [ROUNDS (default 3)] [CSV]
#include "BenchSupport.h"
#include "HeatDiffusion_CPU.h"
#include "HeatDiffusion_Vulkan.h"
#include "solver_loops.h"
#ifdef CROSSRT_HAS_ISPC
#include "HeatDiffusion_ISPC.h"
#endif
#include "CommandLine.h"

#include <crossrt/IspcSupport.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace {

struct Row {
  std::string impl, solve;
  std::function<std::shared_ptr<HeatDiffusion>()> make;
  std::function<void(HeatDiffusion&)> run;
  std::vector<double> ms;
  int steps = 0;
};

}  // namespace

int main(int argc, char** argv)
{
  int side = 64, rounds = 3;
  std::string csvPath = "out/bench_solver.csv";
  crossrt::CommandLine app("bench_solver",
                           "Times HeatDiffusion's solve to convergence (at most 5000 steps) with the residual read every step and\n"
                           "every k steps, on the original class, _CPU, _ISPC and _Vulkan, in interleaved rounds.");
  app.add_option("SIDE", side, "grid cells per side")->check(CLI::Range(3, 1 << 14));
  app.add_option("ROUNDS", rounds, "interleaved rounds")->check(crossrt::Positive());
  app.add_option("CSV", csvPath, "the table's CSV file");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  std::filesystem::create_directories(std::filesystem::path(csvPath).parent_path().empty() ? "." : std::filesystem::path(csvPath).parent_path());
  std::ofstream csv(csvPath);
  if (!csv)
  {
    std::fprintf(stderr, "bench_solver: cannot write %s\n", csvPath.c_str());
    return 1;
  }
  std::shared_ptr<crossrt::VulkanContext> ctx;
  try
  {
    ctx = crossrt::VulkanContext::CreateDefault();
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "no Vulkan device, the _Vulkan rows are skipped: %s\n", e.what());
  }
  const float tolerance = 1e-3f;
  const int maxSteps = 5000;
  std::vector<std::pair<std::string, std::function<std::shared_ptr<HeatDiffusion>()>>> impls = {
      {"original", [&] { return std::make_shared<HeatDiffusion>(side, side); }},
      {"_CPU", [&] { return CreateHeatDiffusion_CPU(side, side); }},
  };
#ifdef CROSSRT_HAS_ISPC
  impls.push_back({"_ISPC", [&] { return CreateHeatDiffusion_ISPC(side, side); }});
#endif
  if (ctx) impls.push_back({"_Vulkan", [&] { return CreateHeatDiffusion_Vulkan(ctx, side, side); }});
  std::vector<Row> rows;
  for (auto& [impl, make] : impls)
  {
    rows.push_back({impl, "every step", make, [&](HeatDiffusion& d) { d.Solve(maxSteps, tolerance); }, {}, 0});
    for (int k : {10, 100})
      rows.push_back({impl, "every " + std::to_string(k), make, [=](HeatDiffusion& d) { d.SolveChecked(maxSteps, tolerance, k); }, {}, 0});
  }
  for (int round = 0; round < rounds + 1; ++round)  // round 0 warms up (pipelines, page faults)
    for (Row& r : rows)
    {
      std::shared_ptr<HeatDiffusion> d = r.make();
      d->CommitDeviceData();
      const auto t0 = std::chrono::steady_clock::now();
      r.run(*d);
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      if (round > 0) r.ms.push_back(ms);
      r.steps = d->Steps();
    }
  std::printf("CPU: %s, %u threads; ISPC target: %s (%s); Vulkan device: %s\n", CpuModel().c_str(), std::thread::hardware_concurrency(),
              crossrt::IspcTargetInUse().c_str(), IspcLanes(), ctx ? ctx->DeviceName().c_str() : "none");
  std::printf("HeatDiffusion %dx%d, tolerance %g, at most %d steps; median of %d interleaved rounds\n\n", side, side, tolerance, maxSteps, rounds);
  std::printf("| %-9s | %-12s | %6s | %10s | %9s | %12s | %14s |\n|%s|\n", "impl", "residual read", "steps", "ms", "us/step",
              "vs original", "vs every step", std::string(90, '-').c_str());
  csv << "implementation,residual_read,steps,ms,us_per_step,speedup_vs_original,speedup_vs_every_step\n";
  std::map<std::string, double> original, everyStep;
  for (Row& r : rows)
  {
    const double ms = MedianOf(r.ms);
    if (r.impl == "original") original[r.solve] = ms;
    if (r.solve == "every step") everyStep[r.impl] = ms;
    const double vsOriginal = original[r.solve] / ms, vsEvery = everyStep[r.impl] / ms;
    std::printf("| %-9s | %-12s | %6d | %10.2f | %9.2f | %11.2fx | %13.2fx |\n", r.impl.c_str(), r.solve.c_str(), r.steps, ms, 1000.0 * ms / r.steps,
                vsOriginal, vsEvery);
    csv << r.impl << "," << r.solve << "," << r.steps << "," << ms << "," << 1000.0 * ms / r.steps << "," << vsOriginal << "," << vsEvery << "\n";
  }
  std::printf("\nOn Vulkan each read of the residual between kernel calls is a submission and a wait; 'every k' reads it after\n"
              "every k-th step only (and so may run up to k - 1 steps past convergence). CSV: %s\n", csvPath.c_str());
  return 0;
}
