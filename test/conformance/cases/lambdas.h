// Lambdas and range-based for loops in a kernel, as C++ users write them: a local lambda without
// captures, one capturing a local by copy, one adding into a local by reference, one reading a
// member through [this], one called where it is written; and `for (x : range)` over a local array
// and over a member array, nested, and over a member std::vector.
#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <vector>

class LambdaMix
{
public:
  LambdaMix() = default;
  virtual ~LambdaMix() = default;
  virtual void Mix(uint32_t n, const float* a_in [[size("n")]], float* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}
  float m_gain = 1.5f;
  float m_taps[4] = {0.1f, 0.2f, 0.3f, 0.4f};
  std::vector<LiteMath::float2> m_bends = {{0.5f, 0.1f}, {-0.25f, 0.3f}, {1.0f, -0.2f}};

protected:
  void kernel1D_Mix(uint32_t n, const float* a_in, float* a_out);
};
