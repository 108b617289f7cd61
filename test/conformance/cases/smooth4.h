// A local array of vectors in a kernel: float2 taps[4].
#pragma once
#include "LiteMath.h"
using LiteMath::float2;

class Smooth4
{
public:
  virtual void Run(int n, const float2* a_in [[size("n")]], float2* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Run(int n, const float2* a_in, float2* a_out);
};
