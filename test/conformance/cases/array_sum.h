// size_t kernel parameters (kernel_slicer's 001/016 form): 32-bit on the GPU.
#pragma once
#include "LiteMath.h"
#include <cstddef>

class ArraySum
{
public:
  virtual void CalcArraySum(const int* a_data [[size("a_dataSize")]], unsigned int a_dataSize);
  virtual void CommitDeviceData() {}
  int m_sum = 0;

protected:
  virtual void kernel1D_ArraySum(const int* a_data, size_t a_dataSize);
};
