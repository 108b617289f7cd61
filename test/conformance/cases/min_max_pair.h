// A helper that returns two results through pointers to the caller's locals: Split(a, b, &lo, &hi).
#pragma once
#include "LiteMath.h"

class MinMaxPair
{
public:
  virtual void Run(int n, const float* a_a [[size("n")]], const float* a_b [[size("n")]], float* a_lo [[size("n")]], float* a_hi [[size("n")]]);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Run(int n, const float* a_a, const float* a_b, float* a_lo, float* a_hi);
};
