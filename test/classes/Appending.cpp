#include "Appending.h"

void Appending::Select(int n, float threshold, const float* values, float* out)
{
  m_positive.clear();
  m_large.clear();
  kernel1D_FindPositive(n, values);
  kernel1D_FindLarge(threshold, values);
  kernel1D_Write(out);
}

void Appending::Collect(int n, const float* values)
{
  kernel1D_FindNegative(n, values);
}

void Appending::kernel1D_FindPositive(int n, const float* values)
{
  for (int i = 0; i < n; ++i)
    if (values[i] > 0.0f)
      m_positive.push_back(uint32_t(i));
}

void Appending::kernel1D_FindLarge(float threshold, const float* values)
{
  for (uint32_t i = 0; i < m_positive.size(); ++i)
  {
    const uint32_t index = m_positive[i];
    if (values[index] > threshold)
      m_large.push_back(Candidate{index, 2.0f * values[index]});
  }
}

void Appending::kernel1D_Write(float* out)
{
  for (uint32_t i = 0; i < m_large.size(); ++i)
    out[m_large[i].index] = m_large[i].value;
}

void Appending::kernel1D_FindNegative(int n, const float* values)
{
  for (int i = 0; i < n; ++i)
    if (values[i] < 0.0f)
      m_negative.push_back(uint32_t(i));
}
