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

void Usage(FILE* to)
{
  std::fprintf(to,
               "usage: radiance_fields train DATASET_DIR --out MODEL [--device original|cpu|vulkan] [--grid N] [--iters K]\n"
               "                             [--batch B] [--sh 0|1|2] [--lr RATE] [--seed S]\n"
               "       radiance_fields render MODEL --dataset DATASET_DIR --out DIR [--split test] [--device original|cpu|vulkan]\n"
               "                             [--method bvh|march] [--stop T]\n"
               "       radiance_fields synthetic DIR [--views N] [--size S]\n"
               "\n"
               "train   fits a ReLU field (density and colour as spherical harmonics on a grid) to the dataset's\n"
               "        transforms_train.json images: stages of N/8, N/4, N/2 and N cells (--grid, default 64; at\n"
               "        least 8 cells a stage), K iterations each (--iters, default 300) of B random rays (--batch,\n"
               "        default 4096). A progress bar on stderr gives the stage, loss, iterations per second and the\n"
               "        PSNR of one held-out view (transforms_val.json, else the first test view).\n"
               "render  renders every frame of a split (--split, default test) to DIR/<the frame's file name>.png at\n"
               "        the dataset image's size, prints each view's PSNR against the dataset's image, the mean and\n"
               "        the milliseconds per frame. --method bvh visits the occupied cells front to back, one\n"
               "        sample each (the default); march takes constant steps of half a cell. --stop ends a ray\n"
               "        once its transmittance falls below T (default 0.01).\n"
               "synthetic writes transforms_train.json (N views, default 60) and transforms_test.json (8 views) of\n"
               "        an analytic scene, a shaded sphere and a box, S x S pixels (default 64), rendered exactly.\n"
               "\n"
               "--device picks the class as written (original), ReluField_CPU (cpu, the default) or\n"
               "ReluField_Vulkan (vulkan, the default Vulkan device).\n");
}

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

int IntArg(const char* name, const char* text)
{
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (!*text || *end || v < 0 || v > 1 << 24)
    Fail(std::string(name) + " takes a non-negative integer, not '" + text + "'");
  return int(v);
}

float FloatArg(const char* name, const char* text)
{
  char* end = nullptr;
  const float v = std::strtof(text, &end);
  if (!*text || *end || !std::isfinite(v) || v < 0.0f)
    Fail(std::string(name) + " takes a non-negative number, not '" + text + "'");
  return v;
}

Args Parse(int argc, char** argv)
{
  Args a;
  for (int i = 2; i < argc; ++i)
  {
    const std::string s = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc)
        Fail(s + " needs a value");
      return argv[++i];
    };
    if (s == "--out") a.out = value();
    else if (s == "--device") a.device = value();
    else if (s == "--dataset") a.dataset = value();
    else if (s == "--split") a.split = value();
    else if (s == "--method") a.method = value();
    else if (s == "--grid") a.grid = IntArg("--grid", value());
    else if (s == "--iters") a.iterations = IntArg("--iters", value());
    else if (s == "--batch") a.batch = IntArg("--batch", value());
    else if (s == "--sh") a.sh = IntArg("--sh", value());
    else if (s == "--views") a.views = IntArg("--views", value());
    else if (s == "--size") a.size = IntArg("--size", value());
    else if (s == "--seed") a.seed = uint32_t(IntArg("--seed", value()));
    else if (s == "--lr") a.lr = FloatArg("--lr", value());
    else if (s == "--stop") a.stop = FloatArg("--stop", value());
    else if (!s.empty() && s[0] == '-') Fail("unknown option " + s + " (see --help)");
    else a.positional.push_back(s);
  }
  if (a.device != "original" && a.device != "cpu" && a.device != "vulkan")
    Fail("--device takes original, cpu or vulkan, not '" + a.device + "'");
  if (a.method != "bvh" && a.method != "march")
    Fail("--method takes bvh or march, not '" + a.method + "'");
  if (a.sh > 2)
    Fail("--sh takes 0, 1 or 2");
  return a;
}

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
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h"))
  {
    Usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  for (int i = 2; i < argc; ++i)
    if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h"))
    {
      Usage(stdout);
      return 0;
    }
  const std::string command = argv[1];
  const Args a = Parse(argc, argv);
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
  Fail("unknown command '" + command + "': train, render or synthetic (see --help)");
}
