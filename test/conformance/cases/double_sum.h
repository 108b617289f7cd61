// double in kernels (kernel_slicer's 016_double_v1): a CPU class needs none of the GPU's limits.
#pragma once
#include "LiteMath.h"
#include <cstddef>

class DoubleSum
{
public:
  virtual void Sum(const double* a_data [[size("a_dataSize")]], size_t a_dataSize);
  virtual void CommitDeviceData() {}
  double m_summ = 0.0;

protected:
  void kernel1D_Sum(const double* a_data, size_t a_dataSize);
};
