#include "RFTraining.h"

#include <chrono>
#include <random>
#include <stdexcept>

namespace literf {

using LiteMath::float3;
using LiteMath::float4;

RFGrid ReadGrid(ReluField& field, const RFGrid& shape)
{
  RFGrid out = shape;
  if (field.ValueCount() != int(out.values.size()))
    throw std::runtime_error("the field holds " + std::to_string(field.ValueCount()) + " values, not the " + std::to_string(out.values.size()) + " of its grid");
  field.ReadValues(int(out.values.size()), out.values.data());
  return out;
}

RFGrid Train(ReluField& field, const NerfSplit& train, const TrainOptions& options, const std::function<void(const TrainProgress&)>& progress)
{
  if (train.frames.empty() || train.frames[0].image.width() == 0)
    throw std::runtime_error("training needs a split with its images");
  if (options.stages.empty() || options.iterations < 1 || options.batch < 1)
    throw std::runtime_error("training needs at least one stage, iteration and ray per batch");
  const float focal = train.Focal();
  std::mt19937 rng(options.seed);
  std::uniform_int_distribution<size_t> pickFrame(0, train.frames.size() - 1);
  std::uniform_int_distribution<int> pickX(0, train.width - 1), pickY(0, train.height - 1);
  std::vector<float4> origins(size_t(options.batch)), dirs(size_t(options.batch)), targets(size_t(options.batch));
  std::vector<float> losses(size_t(options.batch));

  field.SetLearningRate(options.learningRate);
  field.SetMarchStep(options.marchStep);
  field.SetStopTransmittance(options.stopTransmittance);
  RFGrid grid;
  TrainProgress p;
  p.stages = int(options.stages.size());
  for (size_t stage = 0; stage < options.stages.size(); ++stage)
  {
    const int cells = options.stages[stage];
    if (stage == 0)
      grid = MakeGrid(cells, options.shDegree, options.initialRawDensity, options.boxMin, options.boxMax);
    else
      grid = Upsample(grid, cells);
    p.occupiedCells = Prune(grid, stage == 0 ? 0.0f : options.pruneAlpha);
    field.SetGrid(grid);
    field.CommitDeviceData();
    p.stage = int(stage);
    p.cells = cells;
    p.iterations = options.iterations;
    const auto start = std::chrono::steady_clock::now();
    for (int it = 0; it < options.iterations; ++it)
    {
      for (int r = 0; r < options.batch; ++r)
      {
        const NerfFrame& frame = train.frames[pickFrame(rng)];
        const int x = pickX(rng), y = pickY(rng);
        float3 o, d;
        PixelRay(frame.cameraToWorld, focal, train.width, train.height, x, y, o, d);
        origins[size_t(r)] = float4(o.x, o.y, o.z, 0.0f);
        dirs[size_t(r)] = float4(d.x, d.y, d.z, 0.0f);
        targets[size_t(r)] = frame.image.data()[size_t(y) * train.width + x];
      }
      field.TrainStep(options.batch, origins.data(), dirs.data(), targets.data(), losses.data());
      double sum = 0.0;
      for (float l : losses)
        sum += l;
      p.iteration = it + 1;
      p.loss = float(sum / options.batch);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      p.iterationsPerSecond = seconds > 0.0 ? float((it + 1) / seconds) : 0.0f;
      if (progress)
        progress(p);
    }
    grid = ReadGrid(field, grid);
  }
  Prune(grid, options.pruneAlpha);
  return grid;
}

void RenderFrame(ReluField& field, const NerfSplit& split, const NerfFrame& frame, LiteImage::Image2D<float4>& out)
{
  out = LiteImage::Image2D<float4>(uint32_t(split.width), uint32_t(split.height));
  field.SetCamera(frame.cameraToWorld, split.Focal());
  field.Render(out.data());
}

float SplitPsnr(ReluField& field, const NerfSplit& split)
{
  float sum = 0.0f;
  for (const NerfFrame& f : split.frames)
  {
    LiteImage::Image2D<float4> image;
    RenderFrame(field, split, f, image);
    sum += Psnr(image, f.image);
  }
  return split.frames.empty() ? 0.0f : sum / float(split.frames.size());
}

}  // namespace literf
