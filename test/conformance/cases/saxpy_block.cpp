#include "saxpy_block.h"

void SaxpyBlock::RunBlock(uint32_t n, float a, const float* x, const float* y, float* out)
{
  #pragma omp parallel for
  for (uint32_t i = 0; i < n; i++)
    Run(i, a, x, y, out);
}

void SaxpyBlock::Run(uint32_t tid, float a, const float* x, const float* y, float* out)
{
  float temp;
  kernel_Mul(tid, a, x, &temp);
  kernel_Add(tid, &temp, y, out);
}

void SaxpyBlock::kernel_Mul(uint32_t tid, float a, const float* x, float* temp) { *temp = a * x[tid]; }

void SaxpyBlock::kernel_Add(uint32_t tid, const float* temp, const float* y, float* out) { out[tid] = *temp + y[tid]; }
