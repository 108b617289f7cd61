// LiteMath's functions of float vectors, per component, as a shader-minded user calls them in a
// kernel: floor, ceil, fract, sign, sqrt, inversesqrt, sin, cos, exp, log, pow, step, mod, lerp, mix
// and smoothstep, on float2, float3 and float4.
#pragma once
#include "LiteMath.h"

class VectorFuncs
{
public:
  VectorFuncs() {}
  virtual ~VectorFuncs() {}
  virtual void CommitDeviceData() {}
  // a_out[16 * i + k]: the k-th function of a_in[i] (its xyz, xy or all four components).
  virtual void Apply(const LiteMath::float4* a_in [[size("n")]], LiteMath::float4* a_out [[size("16 * n")]], int n);

protected:
  void kernel1D_Apply(const LiteMath::float4* a_in, LiteMath::float4* a_out, int n);
};
