// Arithmetic in double: a double buffer, member, member vector and local array, a static helper
// of double, 1.0 / 3.0 and an int added in double. Runs as written on the CPU backends; Vulkan refuses double by design.
#pragma once
#include "LiteMath.h"
#include <vector>

class DoubleScale
{
public:
  virtual void Scale(int n, const float* a_in [[size("n")]], double* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}
  double m_offset = 0.1;
  std::vector<double> m_weights = {1.0, 0.1, 0.01, 0.001};

protected:
  void kernel1D_Scale(int n, const float* a_in, double* a_out);
};
