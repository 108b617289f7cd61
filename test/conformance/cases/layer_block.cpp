#include "layer_block.h"

void LayerBlock::AddBlock(uint32_t n, uint32_t a_layers, float* out)
{
  (void)a_layers;  // the layers are Add's business: three
  for (uint32_t i = 0; i < n; i++)
    Add(i, 3, out);
}

void LayerBlock::Add(uint32_t tid, uint32_t a_layers, float* out)
{
  float amount = 1.5f;  // every thread starts at the same value, and halves it per layer
  for (uint32_t layer = 0; layer < a_layers; layer++)
    kernel_AddOne(tid, &amount, out);
  kernel_Halve(tid, out);
}

void LayerBlock::kernel_AddOne(uint32_t tid, float* amount, float* out)
{
  out[tid] += *amount + 0.5f * float(tid % 4);
  *amount *= 0.5f;
}

void LayerBlock::QuarterBlock(float* out, uint32_t a_count)
{
  for (uint32_t tid = 0; tid < a_count; tid++)
    Quarter(out, tid);
}

void LayerBlock::Quarter(float* out, uint32_t tid)
{
  kernel_Halve(tid, out);
  kernel_Halve(tid, out);
}

void LayerBlock::kernel_Halve(uint32_t tid, float* out) { out[tid] *= 0.5f; }
