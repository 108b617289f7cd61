#include "point_stats.h"

void PointStats::Compute(uint32_t n, const float4* a_points, float4* a_summary)
{
  kernel1D_Compute(n, a_points, a_summary);
}

void PointStats::kernel1D_Compute(uint32_t n, const float4* a_points, float4* a_summary)
{
  m_boxMin = float4(+1e6f, +1e6f, +1e6f, +1e6f);
  m_boxMax = float4(-1e6f, -1e6f, -1e6f, -1e6f);
  m_sumX = 0.0f;
  const float scale = 0.5f;
  for (uint32_t i = 0; i < n; i++)
  {
    const float4 p = a_points[i] * scale;
    m_boxMin = min(m_boxMin, p);
    m_boxMax = max(m_boxMax, p);
    m_sumX += p.x;
  }
  a_summary[0] = m_boxMin;
  a_summary[1] = m_boxMax;
  a_summary[2] = float4(m_sumX / float(n), float(n), scale, 0.0f);
}
