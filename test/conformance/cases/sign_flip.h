// std::copysign and copysign in a kernel (signed zeros and infinities included).
#pragma once
#include "LiteMath.h"

class SignFlip
{
public:
  virtual void Run(int n, const float* a_mag [[size("n")]], const float* a_sign [[size("n")]], float* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Run(int n, const float* a_mag, const float* a_sign, float* a_out);
};
