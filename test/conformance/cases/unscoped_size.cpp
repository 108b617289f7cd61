#include "unscoped_size.h"

void Saxpy::Run(uint32_t n, const float* x, const float* y, float* out) { kernel1D_Saxpy(n, x, y, out); }

void Saxpy::kernel1D_Saxpy(uint32_t n, const float* x, const float* y, float* out)
{
  for (uint32_t i = 0; i < n; i++)
    out[i] = m_a * x[i] + y[i];
}
