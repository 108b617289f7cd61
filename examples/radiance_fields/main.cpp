// radiance_fields: trains a ReLU field from a NeRF synthetic ("Blender") dataset and renders it, on
// the class as written, ReluField_CPU (all cores) or ReluField_Vulkan (the default device).
//   radiance_fields train DATASET_DIR --out MODEL [options]
//   radiance_fields render MODEL --dataset DATASET_DIR --out DIR [options]
//   radiance_fields synthetic DIR: writes a small dataset of an analytic scene (for trying it out).
#include "AnalyticScene.h"
#include "NerfDataset.h"
#include "RFTraining.h"
#include "ReluField.h"
#include "ReluField_CPU.h"
#include "ReluField_Vulkan.h"

#include "CommandLine.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

using namespace literf;
using LiteMath::float3;
using LiteMath::float4;

namespace {

[[noreturn]] void Fail(const std::string& message)
{
  std::fprintf(stderr, "radiance_fields: error: %s\n", message.c_str());
  std::exit(1);
}

struct Args
{
  std::vector<std::string> positional;
  std::string out, device = "cpu", dataset, split = "test", method = "bvh";
  int grid = 64, iterations = 300, batch = 4096, sh = 2, views = 60, size = 64;
  float lr = 0.01f, stop = 0.01f;
  uint32_t seed = 1;
};

// The field on the device asked for.
std::shared_ptr<ReluField> MakeField(const std::string& device, int width, int height)
{
  if (device == "original")
    return std::make_shared<ReluField>(width, height);
  if (device == "cpu")
    return CreateReluField_CPU(width, height);
  std::shared_ptr<crossrt::VulkanContext> ctx;
  try
  {
    ctx = crossrt::VulkanContext::CreateDefault();
  }
  catch (const std::exception& e)
  {
    Fail(std::string("--device vulkan: no Vulkan device: ") + e.what());
  }
  std::fprintf(stderr, "radiance_fields: Vulkan device: %s\n", ctx->properties.deviceName);
  return std::make_shared<ReluField_Vulkan>(ctx, width, height);
}

int Train(const Args& a)
{
  if (a.positional.size() != 1 || a.out.empty())
    Fail("train takes DATASET_DIR and --out MODEL (see --help)");
  const std::string dir = a.positional[0];
  const NerfSplit train = LoadNerfSplit(dir, "train");
  // One held-out view for the progress bar.
  const bool hasVal = HasNerfSplit(dir, "val");
  NerfSplit held = LoadNerfSplit(dir, hasVal ? "val" : "test");
  held.frames.resize(1);
  std::fprintf(stderr, "radiance_fields: %zu training views of %dx%d; held-out view %s from %s\n", train.frames.size(), train.width, train.height,
               held.frames[0].filePath.c_str(), hasVal ? "val" : "test");

  TrainOptions options;
  options.stages.clear();
  for (int div : {8, 4, 2, 1})
    if (a.grid / div >= 8 && (options.stages.empty() || options.stages.back() != a.grid / div))
      options.stages.push_back(a.grid / div);
  if (options.stages.empty())
    Fail("--grid must be at least 8 cells");
  options.iterations = std::max(a.iterations, 1);
  options.batch = std::max(a.batch, 1);
  options.shDegree = a.sh;
  options.learningRate = a.lr;
  options.seed = a.seed;
  auto field = MakeField(a.device, held.width, held.height);
  auto viewer = std::make_shared<ReluField>(held.width, held.height);  // renders the held-out view
  float psnr = 0.0f;
  int lastStage = -1;
  const auto start = std::chrono::steady_clock::now();
  RFGrid grid = literf::Train(*field, train, options, [&](const TrainProgress& p) {
    if (p.iteration == p.iterations)  // a stage ends: the held-out view's PSNR
    {
      RFGrid now = ReadGrid(*field, MakeGrid(p.cells, options.shDegree, 0.0f, options.boxMin, options.boxMax));
      viewer->SetGrid(now);
      LiteImage::Image2D<float4> image;
      RenderFrame(*viewer, held, held.frames[0], image);
      psnr = Psnr(image, held.frames[0].image);
    }
    if (p.stage != lastStage || p.iteration % 10 == 0 || p.iteration == p.iterations)
    {
      const int width = 30, done = width * p.iteration / p.iterations;
      std::fprintf(stderr, "\rstage %d/%d %3d^3 [%s%s] %4d/%d  loss %.5f  %.1f it/s  held-out PSNR %s   ", p.stage + 1, p.stages, p.cells,
                   std::string(size_t(done), '#').c_str(), std::string(size_t(width - done), '.').c_str(), p.iteration, p.iterations, p.loss,
                   p.iterationsPerSecond, psnr > 0.0f ? (std::to_string(psnr).substr(0, 5) + " dB").c_str() : "-");
      if (p.iteration == p.iterations)
        std::fprintf(stderr, "\n");
      lastStage = p.stage;
    }
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  SaveModel(a.out, grid);
  const std::vector<uint8_t> occupied = OccupiedCells(grid);
  size_t count = 0;
  for (uint8_t o : occupied)
    count += o;
  std::printf("trained %d^3 cells (SH degree %d) in %.1f s on %s: %zu cells occupied, %.1f MB; held-out PSNR %.2f dB; wrote %s\n", grid.cells,
              grid.shDegree, seconds, a.device.c_str(), count, double(grid.Bytes()) / 1e6, psnr, a.out.c_str());
  return 0;
}

int Render(const Args& a)
{
  if (a.positional.size() != 1 || a.dataset.empty() || a.out.empty())
    Fail("render takes MODEL, --dataset DATASET_DIR and --out DIR (see --help)");
  const RFGrid grid = LoadModel(a.positional[0]);
  const NerfSplit split = LoadNerfSplit(a.dataset, a.split);
  auto field = MakeField(a.device, split.width, split.height);
  field->SetGrid(grid);
  field->SetMethod(a.method == "bvh" ? ReluField::kCells : ReluField::kMarch);
  field->SetStopTransmittance(a.stop);
  field->CommitDeviceData();
  std::filesystem::create_directories(a.out);
  double sum = 0.0, ms = 0.0;
  for (const NerfFrame& f : split.frames)
  {
    LiteImage::Image2D<float4> image;
    const auto start = std::chrono::steady_clock::now();
    RenderFrame(*field, split, f, image);
    const double frameMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const float psnr = Psnr(image, f.image);
    const std::string name = std::filesystem::path(f.filePath).filename().string() + ".png";
    const std::string path = (std::filesystem::path(a.out) / name).string();
    if (!LiteImage::SaveImage(path.c_str(), image))
      Fail("cannot write " + path);
    std::printf("%-12s PSNR %6.2f dB  %8.1f ms\n", name.c_str(), psnr, frameMs);
    sum += psnr;
    ms += frameMs;
  }
  const double n = double(split.frames.size());
  std::printf("mean PSNR %.2f dB over %zu views of %s; %.1f ms per %dx%d frame (%s, %s)\n", sum / n, split.frames.size(), a.split.c_str(), ms / n,
              split.width, split.height, a.device.c_str(), a.method.c_str());
  return 0;
}

int Synthetic(const Args& a)
{
  if (a.positional.size() != 1)
    Fail("synthetic takes DIR (see --help)");
  if (a.size < 8 || a.views < 1)
    Fail("synthetic needs --size of at least 8 and at least one view");
  for (const auto& [split, views] : {std::pair<std::string, int>{"train", a.views}, std::pair<std::string, int>{"test", 8}})
    SaveNerfSplit(a.positional[0], split, MakeAnalyticSplit(split, views, a.size, split == "train" ? a.seed : a.seed + 1000u));
  std::printf("wrote %d training and 8 test views of %dx%d to %s\n", a.views, a.size, a.size, a.positional[0].c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv)
{
  Args a;
  crossrt::CommandLine app("radiance_fields",
                           "Fits, renders and makes radiance fields (ReLU fields: density and colour as spherical harmonics on a grid)\n"
                           "with the class as written (--device original), ReluField_CPU (cpu) or ReluField_Vulkan (vulkan, the\n"
                           "default Vulkan device).");
  app.require_subcommand(1);
  auto device = [&](CLI::App* command) {
    command->add_option("--device", a.device, "the class that runs it")->check(CLI::IsMember({"original", "cpu", "vulkan"}));
  };
  CLI::App* train = app.add_subcommand(
      "train",
      "fits a ReLU field to the dataset's transforms_train.json images: stages of N/8, N/4, N/2 and N cells\n"
      "(--grid; at least 8 cells a stage), K iterations each (--iters) of B random rays (--batch). A progress bar\n"
      "on stderr gives the stage, loss, iterations per second and the PSNR of one held-out view\n"
      "(transforms_val.json, else the first test view).");
  train->add_option("DATASET_DIR", a.positional, "the dataset (the NeRF format: transforms_*.json and images)");
  train->add_option("--out", a.out, "the model file to write");
  device(train);
  train->add_option("--grid", a.grid, "cells per axis, N")->check(crossrt::NonNegative());
  train->add_option("--iters", a.iterations, "iterations per stage, K")->check(crossrt::NonNegative());
  train->add_option("--batch", a.batch, "rays per iteration, B")->check(crossrt::NonNegative());
  train->add_option("--sh", a.sh, "degree of the spherical harmonics")->check(CLI::Range(0, 2));
  train->add_option("--lr", a.lr, "learning rate")->check(CLI::NonNegativeNumber);
  train->add_option("--seed", a.seed, "the random sequence of rays");
  CLI::App* render = app.add_subcommand(
      "render",
      "renders every frame of a split to DIR/<the frame's file name>.png at the dataset image's size, prints each\n"
      "view's PSNR against the dataset's image, the mean and the milliseconds per frame.");
  render->add_option("MODEL", a.positional, "the model file");
  render->add_option("--dataset", a.dataset, "the dataset whose views are rendered");
  render->add_option("--out", a.out, "the folder of images to write");
  render->add_option("--split", a.split, "the dataset's split");
  device(render);
  render->add_option("--method", a.method, "bvh: the occupied cells front to back, one sample each; march: constant steps of half a cell")
      ->check(CLI::IsMember({"bvh", "march"}));
  render->add_option("--stop", a.stop, "a ray ends once its transmittance falls below this")->check(CLI::NonNegativeNumber);
  CLI::App* synthetic = app.add_subcommand(
      "synthetic",
      "writes transforms_train.json (N views) and transforms_test.json (8 views) of an analytic scene, a shaded sphere\n"
      "and a box, S x S pixels, rendered exactly.");
  synthetic->add_option("DIR", a.positional, "the dataset folder to write");
  synthetic->add_option("--views", a.views, "training views, N")->check(crossrt::NonNegative());
  synthetic->add_option("--size", a.size, "width and height in pixels, S")->check(crossrt::NonNegative());
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  const std::string command = app.get_subcommands().front()->get_name();
  try
  {
    if (command == "train")
      return Train(a);
    if (command == "render")
      return Render(a);
    if (command == "synthetic")
      return Synthetic(a);
  }
  catch (const std::exception& e)
  {
    Fail(e.what());
  }
  Fail("unknown command '" + command + "'");
}
