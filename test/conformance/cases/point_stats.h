// Statements before a kernel's loop nest (reductions set up) and after it (a one-thread epilogue):
// the paper's loop_start and loop_end.
#pragma once
#include "LiteMath.h"
#include <cstdint>
using namespace LiteMath;

class PointStats
{
public:
  PointStats() {}
  virtual void Compute(uint32_t n, const float4* a_points [[size("n")]], float4* a_summary [[size("3")]]);
  virtual void CommitDeviceData() {}

  float4 m_boxMin, m_boxMax;
  float m_sumX = 0.0f;

protected:
  void kernel1D_Compute(uint32_t n, const float4* a_points, float4* a_summary);
};
