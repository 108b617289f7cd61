#include "local_totals.h"

#include <algorithm>

void LocalTotals::Summarize(uint32_t n, const float4* a_values, float* a_out) { kernel1D_Summarize(n, a_values, a_out); }

void LocalTotals::kernel1D_Summarize(uint32_t n, const float4* a_values, float* a_out)
{
  float sum = 0.0f;
  float lo = 1e30f;
  float hi = -1e30f;
  float4 total = float4(1.0f, 2.0f, 3.0f, 4.0f);
  int negatives = 0;
  for (uint32_t i = 0; i < n; i++)
  {
    const float v = a_values[i].x;
    sum += v;
    lo = std::min(lo, v);
    hi = std::max(v, hi);
    total += a_values[i];
    if (v < 0.0f)
      negatives++;
  }
  m_mean = n > 0 ? sum / float(n) : 0.0f;
  m_range = hi - lo;
  a_out[0] = sum;
  a_out[1] = lo;
  a_out[2] = hi;
  a_out[3] = total.x;
  a_out[4] = total.y;
  a_out[5] = total.z;
  a_out[6] = total.w;
  a_out[7] = float(negatives);
}
