#include "smooth4.h"

void Smooth4::Run(int n, const float2* a_in, float2* a_out) { kernel1D_Run(n, a_in, a_out); }

void Smooth4::kernel1D_Run(int n, const float2* a_in, float2* a_out)
{
  for (int i = 0; i < n; i++)
  {
    float2 taps[4];
    for (int k = 0; k < 4; k++)
      taps[k] = a_in[(i + k) % n] * float(k + 1);
    float weights[4] = {0.1f, 0.2f, 0.3f, 0.4f};
    float2 sum(0.0f, 0.0f);
    for (int k = 0; k < 4; k++)
      sum += taps[k] * weights[k];
    a_out[i] = sum;
  }
}
