#include "Scale.h"

void Scale::Run(int n, const float* in, float* out) { kernel1D_Scale(n, in, out); }

void Scale::kernel1D_Scale(int n, const float* in, float* out) {
  for (int i = 0; i < n; ++i)
    out[i] = in[i] * m_factor;
}
