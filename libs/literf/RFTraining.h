// Coarse-to-fine training of a ReLU field from a NeRF split (ReLU Fields' schedule): a stage per grid
// size, each started from the last one upsampled and pruned, with batches of random pixels' rays
// and Adam. The field runs on whichever ReluField it is given (the original, _CPU or _Vulkan).
#pragma once
#include "NerfDataset.h"
#include "ReluField.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace literf {

struct TrainOptions
{
  std::vector<int> stages = {16, 32, 64, 128};  // cells per axis of each stage's grid
  int iterations = 500;                         // per stage
  int batch = 4096;                             // rays per iteration
  int shDegree = 2;
  float learningRate = 0.01f;       // Adam moves every value by about this at first: at 0.03 the first step switched every density off
  float initialRawDensity = 0.02f;  // every vertex's raw density at the start (density 2 at scale 100): above a step
  float pruneAlpha = 1e-3f;         // cells less opaque than this are emptied between stages
  float marchStep = 0.5f;           // in cells
  float stopTransmittance = 0.01f;
  uint32_t seed = 1;
  LiteMath::float3 boxMin = LiteMath::float3(-1.5f, -1.5f, -1.5f), boxMax = LiteMath::float3(1.5f, 1.5f, 1.5f);
};

struct TrainProgress
{
  int stage = 0, stages = 0, cells = 0;
  int iteration = 0, iterations = 0;  // within the stage
  float loss = 0.0f;                  // the batch's mean squared error
  float iterationsPerSecond = 0.0f;
  size_t occupiedCells = 0;
};

// Trains on `train` (images loaded) with `field`, whose Render is not used. Calls `progress` after
// every iteration. Returns the trained grid.
RFGrid Train(ReluField& field, const NerfSplit& train, const TrainOptions& options, const std::function<void(const TrainProgress&)>& progress);

// The grid `field` holds now (ReadValues into a copy of `shape`).
RFGrid ReadGrid(ReluField& field, const RFGrid& shape);

// Renders frame `frame` of a split with `field` (constructed at the split's image size and holding
// the grid) into `out`.
void RenderFrame(ReluField& field, const NerfSplit& split, const NerfFrame& frame, LiteImage::Image2D<LiteMath::float4>& out);

// The mean PSNR over a split's frames of `field` (constructed at the split's image size, holding the grid).
float SplitPsnr(ReluField& field, const NerfSplit& split);

}  // namespace literf
