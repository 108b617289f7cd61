#include "threshold_flag.h"

void ThresholdFlag::Check(int n, const float* a_values, float a_limit) { kernel1D_Check(n, a_values, a_limit); }

void ThresholdFlag::kernel1D_Check(int n, const float* a_values, float a_limit)
{
  m_flag = 0;
  for (int i = 0; i < n; i++)
  {
    if (a_values[i] > a_limit)
      m_flag = 1;
  }
}
