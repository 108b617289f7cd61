// A loop that starts in the middle and ends with <=, after a reduction is set up (kernel_slicer's 001/002).
#pragma once
#include "LiteMath.h"

class HalfSum
{
public:
  virtual void Sum(const int* a_data __attribute__((size("a_dataSize"))), unsigned int a_dataSize);
  virtual void CommitDeviceData() {}
  int m_summ = 0;

protected:
  virtual void kernel1D_Sum(const int* a_data, int a_dataSize);
};
