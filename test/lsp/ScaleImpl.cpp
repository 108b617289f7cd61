#include "Scale.h"

void Scale::Run(int n, const float* in, float* out) { kernel1D_Scale(n, in, out); }

void Scale::kernel1D_Scale(int n, const float* in, float* out) {
  for (int i = 0; i < n / 2; ++i) {  // two elements a thread
    out[2 * i] = in[2 * i] * m_factor;
    out[2 * i + 1] = in[2 * i + 1] * m_factor;
  }
}
