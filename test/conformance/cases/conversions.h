// LiteMath's conversions and constants: to_int4(int3, w), int2(float2), float4 -> float3, mod,
// cross3, M_TWOPI, INV_PI.
#pragma once
#include "LiteMath.h"
using namespace LiteMath;

class Conversions
{
public:
  virtual void Run(int n, const float4* a_in [[size("n")]], float4* a_out [[size("n")]], int4* a_ints [[size("n")]]);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Run(int n, const float4* a_in, float4* a_out, int4* a_ints);
};
