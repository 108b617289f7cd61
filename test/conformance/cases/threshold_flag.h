// A member every thread may set to the same value (kernel_slicer's 017: an assignment that is not a reduction).
#pragma once
#include "LiteMath.h"

class ThresholdFlag
{
public:
  virtual void Check(int n, const float* a_values [[size("n")]], float a_limit);
  virtual void CommitDeviceData() {}
  int m_flag = 0;

protected:
  void kernel1D_Check(int n, const float* a_values, float a_limit);
};
