// LiteMath's matrix API as the paper's library has it: mul4x4x4, make_float4x4_from_rows/cols,
// rotate3x3X/Y/Z, float3x3 * float3, columns changed in place (m[k++] += v).
#pragma once
#include "LiteMath.h"
#include <vector>
using namespace LiteMath;

class Transforms
{
public:
  Transforms();
  virtual void Apply(int n, const float4* a_in [[size("n")]], float4* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Apply(int n, const float4* a_in, float4* a_out);
  float4x4 m_rows, m_cols;
  float m_angle = 0.35f;
};
