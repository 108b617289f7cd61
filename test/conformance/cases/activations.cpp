#include "activations.h"

#include <cmath>

void Activations::kernel1D_Apply(const float* a_in, float* a_out, int n)
{
  for (int i = 0; i < n; ++i)
  {
    const float x = a_in[i];
    a_out[6 * i + 0] = std::tanh(x);
    a_out[6 * i + 1] = sinhf(0.5f * x);
    a_out[6 * i + 2] = std::cosh(0.5f * x);
    a_out[6 * i + 3] = std::asinh(x);
    a_out[6 * i + 4] = std::acosh(1.0f + x * x);
    a_out[6 * i + 5] = std::atanh(x / (1.0f + std::abs(x)));
  }
}

void Activations::Apply(const float* a_in, float* a_out, int n) { kernel1D_Apply(a_in, a_out, n); }
