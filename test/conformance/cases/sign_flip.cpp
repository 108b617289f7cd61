#include "sign_flip.h"

#include <cmath>

void SignFlip::Run(int n, const float* a_mag, const float* a_sign, float* a_out) { kernel1D_Run(n, a_mag, a_sign, a_out); }

void SignFlip::kernel1D_Run(int n, const float* a_mag, const float* a_sign, float* a_out)
{
  for (int i = 0; i < n; i++)
    a_out[i] = std::copysign(a_mag[i], a_sign[i]) + copysignf(0.25f, -a_sign[i]);
}
