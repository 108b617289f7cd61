#include "double_scale.h"

static double Twice(double x) { return 2.0 * x; }

void DoubleScale::Scale(int n, const float* a_in, double* a_out) { kernel1D_Scale(n, a_in, a_out); }

void DoubleScale::kernel1D_Scale(int n, const float* a_in, double* a_out)
{
  for (int i = 0; i < n; i++)
  {
    const double third = 1.0 / 3.0;
    double taps[2] = {0.25, 0.7};
    taps[i % 2] += 0.1;
    a_out[i] = Twice(a_in[i] * third) + i * 1e-7 + m_offset * m_weights[i % 4] + taps[i % 2];
  }
}
