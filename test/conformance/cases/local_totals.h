// Reductions into locals: accumulators declared before the loop nest, each thread adding its part,
// and read after it (sum, min, max, a float4 total, a count), with no member to hold them.
#pragma once
#include "LiteMath.h"
#include <cstdint>
using namespace LiteMath;

class LocalTotals
{
public:
  LocalTotals() {}
  virtual void Summarize(uint32_t n, const float4* a_values [[size("n")]], float* a_out [[size(8)]]);
  virtual void CommitDeviceData() {}

  float m_mean = 0.0f;
  float m_range = 0.0f;

protected:
  void kernel1D_Summarize(uint32_t n, const float4* a_values, float* a_out);
};
