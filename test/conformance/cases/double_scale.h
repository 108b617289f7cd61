// Arithmetic in double: a double buffer, a static helper of double, 1.0 / 3.0 and an int added in
// double. Runs as written on the CPU backends; Vulkan refuses double by design.
#pragma once
#include "LiteMath.h"

class DoubleScale
{
public:
  virtual void Scale(int n, const float* a_in [[size("n")]], double* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Scale(int n, const float* a_in, double* a_out);
};
