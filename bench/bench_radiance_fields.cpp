// bench_radiance_fields: ReLU fields (paper 4.3, Tables 7-8) on every backend, from one run.
//   1. training time per iteration: the original (one core), ReluField_CPU and ReluField_Vulkan;
//   2. render time at 800x800 and 1024x1024 for constant-step marching and the occupied-cell tree,
//      on the same three, in interleaved rounds;
//   3. speed against accuracy over the knobs: grid resolution, SH degree and the early-termination
//      threshold, as test PSNR, render time, training time and memory.
// The data is literf's analytic scene (AnalyticScene.h), rendered exactly, so that PSNR measures
// the field and nothing else, and the run needs no dataset. CSV to out/bench_radiance_fields.csv;
// bench/plot_radiance_fields.py plots it.
#include "AnalyticScene.h"
#include "RFCellTree.h"
#include "RFTraining.h"
#include "ReluField.h"
#include "ReluField_CPU.h"
#include "ReluField_Vulkan.h"
#include "CommandLine.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

using namespace literf;
using LiteMath::float4;

namespace {

struct Options
{
  bool quick = false;
  int views = 64, size = 100, iterations = 200;
  std::string csv = "out/bench_radiance_fields.csv";
};

double Seconds(const std::function<void()>& f)
{
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double Median(std::vector<double> v)
{
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

struct Backend
{
  std::string name;
  std::function<std::shared_ptr<ReluField>(int, int)> make;
};

// Coarse-to-fine stages up to `cells`, as radiance_fields train makes them.
TrainOptions Schedule(int cells, int sh, int iterations)
{
  TrainOptions o;
  o.stages.clear();
  for (int div : {8, 4, 2, 1})
    if (cells / div >= 8 && (o.stages.empty() || o.stages.back() != cells / div)) o.stages.push_back(cells / div);
  o.iterations = iterations;
  o.batch = 4096;
  o.shDegree = sh;
  return o;
}

std::shared_ptr<ReluField> Loaded(const Backend& b, const RFGrid& grid, int width, int height, int method, float stop)
{
  auto field = b.make(width, height);
  field->SetGrid(grid);
  field->SetMethod(method);
  field->SetStopTransmittance(stop);
  field->CommitDeviceData();
  return field;
}

size_t TreeBytes(const RFGrid& grid) { return BuildCellTree(grid).size() * sizeof(RFNode); }

}  // namespace

int main(int argc, char** argv)
{
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // each table row as it is measured, even if the run is cut short
  Options opt;
  crossrt::CommandLine app("bench_radiance_fields",
                           "ReLU fields on the original class, ReluField_CPU and ReluField_Vulkan: training time per iteration,\n"
                           "render time at 800x800 and 1024x1024 for marching and the occupied-cell tree, and test PSNR, render\n"
                           "time, training time and memory over grid resolution, SH degree and the early-termination threshold,\n"
                           "trained on N views of S x S pixels of an exactly rendered analytic scene. bench/plot_radiance_fields.py\n"
                           "plots the CSV file.");
  app.add_flag("--quick", opt.quick, "smaller everything, for a smoke run (16 views of 48x48, 40 iterations)");
  app.add_option("--views", opt.views, "training views, N")->check(crossrt::Positive());
  app.add_option("--size", opt.size, "width and height of the views, S")->check(CLI::Range(8, 1 << 14));
  app.add_option("--iters", opt.iterations, "iterations per coarse-to-fine stage")->check(crossrt::Positive());
  app.add_option("--csv", opt.csv, "the table's CSV file");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  if (opt.quick)  // what --quick makes smaller, unless given
  {
    if (!app.count("--views")) opt.views = 16;
    if (!app.count("--size")) opt.size = 48;
    if (!app.count("--iters")) opt.iterations = 40;
  }

  std::vector<Backend> backends = {{"original", [](int w, int h) { return std::make_shared<ReluField>(w, h); }},
                                   {"_CPU", [](int w, int h) { return CreateReluField_CPU(w, h); }}};
  std::shared_ptr<crossrt::VulkanContext> ctx;
  try
  {
    ctx = crossrt::VulkanContext::CreateDefault();
    backends.push_back({"_Vulkan", [ctx](int w, int h) { return std::make_shared<ReluField_Vulkan>(ctx, w, h); }});
  }
  catch (const std::exception& e)
  {
    std::printf("no Vulkan device (%s): _Vulkan left out\n", e.what());
  }
  const Backend& fastest = backends.back();
  const NerfSplit train = MakeAnalyticSplit("train", opt.views, opt.size, 1);
  const NerfSplit test = MakeAnalyticSplit("test", opt.quick ? 4 : 8, opt.size, 2);
  std::printf("Vulkan device: %s; %d training and %zu test views of %dx%d of the analytic scene\n\n", ctx ? ctx->DeviceName().c_str() : "none",
              opt.views, test.frames.size(), opt.size, opt.size);

  std::filesystem::create_directories(std::filesystem::path(opt.csv).parent_path().empty() ? "." : std::filesystem::path(opt.csv).parent_path());
  std::ofstream csv(opt.csv);
  csv << "part,backend,method,grid,sh,stop,size,psnr_db,render_ms,train_s,train_ms_per_iter,memory_mb\n";

  // 1. Training time per iteration: one 64^3 stage (32^3 quick) of 4096-ray batches, after warm-up.
  const int trainCells = opt.quick ? 32 : 64, timedIters = opt.quick ? 6 : 20;
  std::printf("Training, one %d^3 stage of 4096-ray batches, SH degree 2: ms per iteration (after 2 warm-up iterations)\n", trainCells);
  std::printf("| backend  |  ms/iter |  vs original |\n|-------------------------------------|\n");
  double originalMs = 0.0;
  for (const Backend& b : backends)
  {
    TrainOptions o = Schedule(trainCells, 2, timedIters + 2);
    o.stages = {trainCells};
    auto field = b.make(opt.size, opt.size);
    std::chrono::steady_clock::time_point warm;
    double ms = 0.0;
    Train(*field, train, o, [&](const TrainProgress& p) {
      if (p.iteration == 2) warm = std::chrono::steady_clock::now();
      if (p.iteration == p.iterations)
        ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - warm).count() / double(p.iterations - 2);
    });
    if (b.name == "original") originalMs = ms;
    std::printf("| %-8s | %8.2f | %11.2fx |\n", b.name.c_str(), ms, originalMs / ms);
    csv << "train," << b.name << ",," << trainCells << ",2,,,,,," << ms << ",\n" << std::flush;
  }

  // 3 (trained first, rendered in 2 and 3). One model per grid (SH 2) and per SH degree (largest grid).
  const std::vector<int> grids = opt.quick ? std::vector<int>{16, 32} : std::vector<int>{32, 64, 128};
  struct Model { int cells, sh; RFGrid grid; double trainS; };
  std::vector<Model> models;
  auto trainModel = [&](int cells, int sh) {
    auto field = fastest.make(opt.size, opt.size);
    Model m{cells, sh, {}, 0.0};
    m.trainS = Seconds([&] { m.grid = Train(*field, train, Schedule(cells, sh, opt.iterations), [](const TrainProgress&) {}); });
    std::fprintf(stderr, "bench_radiance_fields: trained %d^3, SH %d on %s in %.1f s\n", cells, sh, fastest.name.c_str(), m.trainS);
    models.push_back(std::move(m));
  };
  for (int cells : grids) trainModel(cells, 2);
  for (int sh : {0, 1}) trainModel(grids.back(), sh);
  const Model& best = models[grids.size() - 1];

  // 2. Render time of the best model at 800x800 and 1024x1024, interleaved rounds.
  const std::vector<int> sizes = opt.quick ? std::vector<int>{200} : std::vector<int>{800, 1024};
  const int rounds = opt.quick ? 1 : 3;
  std::map<std::string, std::vector<double>> times;
  for (int round = 0; round < rounds; ++round)
    for (int size : sizes)
      for (const Backend& b : backends)
        for (int method : {ReluField::kMarch, ReluField::kCells})
        {
          if (b.name == "original" && round > 0) continue;  // one core: one round is minutes already
          NerfSplit view = test;
          view.width = view.height = size;
          auto field = Loaded(b, best.grid, size, size, method, 0.01f);
          LiteImage::Image2D<float4> image;
          RenderFrame(*field, view, view.frames[0], image);  // warm-up: pipelines, first upload
          times[std::to_string(size) + b.name + std::to_string(method)].push_back(
              1e3 * Seconds([&] { RenderFrame(*field, view, view.frames[1 % view.frames.size()], image); }));
        }
  std::printf("\nRendering the %d^3 SH 2 field, stop at transmittance 0.01: ms per frame (medians of %d interleaved rounds;\n"
              "the original one round); ratio against marching on the original\n",
              best.cells, rounds);
  std::printf("| size      | backend  |   march ms |    tree ms | tree vs march |  march vs orig |   tree vs orig |\n");
  std::printf("|-------------------------------------------------------------------------------------------------|\n");
  for (int size : sizes)
  {
    const double origMarch = Median(times[std::to_string(size) + "original" + std::to_string(ReluField::kMarch)]);
    for (const Backend& b : backends)
    {
      const double march = Median(times[std::to_string(size) + b.name + std::to_string(ReluField::kMarch)]);
      const double tree = Median(times[std::to_string(size) + b.name + std::to_string(ReluField::kCells)]);
      std::printf("| %4dx%-4d | %-8s | %10.1f | %10.1f | %12.2fx | %13.2fx | %13.2fx |\n", size, size, b.name.c_str(), march, tree, march / tree,
                  origMarch / march, origMarch / tree);
      csv << "render," << b.name << ",march," << best.cells << ",2,0.01," << size << ",," << march << ",,,\n";
      csv << "render," << b.name << ",tree," << best.cells << ",2,0.01," << size << ",," << tree << ",,,\n" << std::flush;
    }
  }

  // 3. Speed against accuracy: test PSNR with the tree on the fastest backend.
  std::printf("\nSpeed against accuracy on %s, the occupied-cell tree, %dx%d test views (%s: coarse-to-fine, %d iterations a stage)\n",
              fastest.name.c_str(), opt.size, opt.size, "trained on the same backend", opt.iterations);
  std::printf("| grid | SH | stop T |  test PSNR dB | render ms |  train s | grid MB | tree MB |\n");
  std::printf("|-------------------------------------------------------------------------------|\n");
  auto row = [&](const Model& m, float stop) {
    auto field = Loaded(fastest, m.grid, opt.size, opt.size, ReluField::kCells, stop);
    SplitPsnr(*field, test);  // warm-up
    double psnr = 0.0;
    const double ms = 1e3 * Seconds([&] { psnr = SplitPsnr(*field, test); }) / double(test.frames.size());
    const double gridMb = double(m.grid.Bytes()) / 1e6, treeMb = double(TreeBytes(m.grid)) / 1e6;
    std::printf("| %4d | %2d | %6.3f | %13.2f | %9.2f | %8.1f | %7.2f | %7.2f |\n", m.cells, m.sh, stop, psnr, ms, m.trainS, gridMb, treeMb);
    csv << "sweep," << fastest.name << ",tree," << m.cells << "," << m.sh << "," << stop << "," << opt.size << "," << psnr << "," << ms << ","
        << m.trainS << ",," << gridMb + treeMb << "\n" << std::flush;
  };
  for (size_t i = 0; i < grids.size(); ++i) row(models[i], 0.01f);
  for (size_t i = grids.size(); i < models.size(); ++i) row(models[i], 0.01f);
  for (float stop : {0.1f, 0.03f, 0.001f, 0.0f}) row(best, stop);
  std::printf("\nwrote %s (plot: /usr/bin/python3 bench/plot_radiance_fields.py %s out/bench_radiance_fields.png)\n", opt.csv.c_str(),
              opt.csv.c_str());
  return 0;
}
