// The unscoped C++11 spelling of the size annotation: [[size("n")]].
#pragma once
#include "LiteMath.h"
#include <cstdint>

class Saxpy
{
public:
  Saxpy(float a) : m_a(a) {}
  virtual void Run(uint32_t n, const float* x [[size("n")]], const float* y [[size("n")]], float* out [[size("n")]]);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Saxpy(uint32_t n, const float* x, const float* y, float* out);
  float m_a;
};
