#include "user_names.h"

Lookalikes::Lookalikes(int n) : m_a(uint32_t(n))
{
  for (int i = 0; i < n; ++i) m_a[uint32_t(i)] = float(i % 5);
}

void Lookalikes::Run(int n, const float* src, float* srcBuffer)
{
  m_total = 0.0f;
  kernel1D_Fill(n, src, srcBuffer);
}

void Lookalikes::kernel1D_Fill(int n, const float* src, float* srcBuffer)
{
  for (int i = 0; i < n; i++)
  {
    const float value = src[i] + m_a[uint32_t(i) % uint32_t(m_a.size())] + float(m_a_size) + 0.5f * float(m_a_capacity) + float(m_a.size()) + m_data.bias;
    srcBuffer[i] = value;
    m_total += value;
  }
}
