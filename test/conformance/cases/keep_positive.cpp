#include "keep_positive.h"

void KeepPositive::Filter(uint32_t n, const float* a_values, uint32_t* a_count)
{
  kernel1D_Filter(n, a_values, a_count);
}

void KeepPositive::kernel1D_Filter(uint32_t n, const float* a_values, uint32_t* a_count)
{
  m_kept.clear();
  for (uint32_t i = 0; i < n; i++)
  {
    if (a_values[i] > 0.0f)
    {
      Kept k;
      k.index = i;
      k.value = a_values[i];
      m_kept.push_back(k);
    }
  }
  *a_count = uint32_t(m_kept.size());
}
