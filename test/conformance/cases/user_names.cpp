#include "user_names.h"

Lookalikes::Lookalikes(int n) : m_a(uint32_t(n)), m_img(4, 2)
{
  for (int i = 0; i < n; ++i) m_a[uint32_t(i)] = float(i % 5);
  for (int x = 0; x < 4; ++x) m_img[LiteMath::int2(x, 1)] = LiteMath::float4(0.5f * float(x));
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
    const float value = src[i] + m_a[uint32_t(i) % uint32_t(m_a.size())] + float(m_a_size) + 0.5f * float(m_a_capacity) + float(m_a.size()) + m_data.bias +
                        float(m_img.width()) + float(m_img_width) + m_img[LiteMath::int2(i % int(m_img.width()), 1)].x +
                        m_totalLocal + m_totalShared + m_totalPartials + m_totalGroup + m_totalSubgroup;
    srcBuffer[i] = value;
    m_total += value;
  }
}
