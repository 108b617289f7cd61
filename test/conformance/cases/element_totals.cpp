#include "element_totals.h"

#include <algorithm>

using LiteMath::float3;
using LiteMath::float4;

// The bin of a value in [0, 1): kBins equal parts, the ends clamped.
static int BinOf(float value)
{
  const int bin = int(value * float(ElementTotals::kBins));
  return std::max(0, std::min(ElementTotals::kBins - 1, bin));
}

void ElementTotals::Measure(int n, const float4* a_samples)
{
  kernel1D_Measure(n, a_samples);
  kernel1D_Extremes(n, a_samples);
}

void ElementTotals::kernel1D_Extremes(int n, const float4* a_samples)
{
  for (int k = 0; k < 3; ++k)
    m_top[k] = 0u;
  m_pairs[0] = m_pairs[1] = LiteMath::int2(0);
  m_counts[0] = m_counts[1] = LiteMath::uint3(7u);
  m_low[0] = m_low[1] = float4(100.0f);
  for (int i = 0; i < n; ++i)
  {
    const float4 s = a_samples[i];
    const uint32_t v = uint32_t(s.w * 1000.0f);
    m_top[i % 3] = std::max(m_top[i % 3], v);
    m_pairs[i & 1] += LiteMath::int2(i % 11, 1);
    m_counts[1] += LiteMath::uint3(1u, v & 1u, 2u);
    m_low[(i / 5) & 1] = min(m_low[(i / 5) & 1], s);
  }
}

void ElementTotals::kernel1D_Measure(int n, const float4* a_samples)
{
  for (int k = 0; k < kMoments; ++k)
    m_moments[k] = float3(0.0f);
  for (int b = 0; b < kBins; ++b)
    m_bins[b] = 0.0f;
  m_least[0] = m_least[1] = 1000000;
  m_count = 0;
  float spread[3] = {0.0f, 0.0f, 0.0f};
  float highest[2] = {-10.0f, -10.0f};
  for (int i = 0; i < n; ++i)
  {
    const float4 s = a_samples[i];
    const float3 d = normalize(float3(s.x, s.y, s.z) + float3(0.0f, 0.0f, 2.0f));
    const float3 colour = float3(s.w, 0.5f * s.w, 1.0f - s.w);
    m_moments[0] += colour;
    m_moments[1] += colour * d.y;
    m_moments[2] += colour * d.z;
    m_moments[3] += colour * d.x;
    m_moments[4] += colour * d.x * d.y;
    m_moments[5] += colour * d.y * d.z;
    m_moments[6] += colour * (2.0f * d.z * d.z - d.x * d.x - d.y * d.y);
    m_moments[7] += colour * d.x * d.z;
    m_moments[8] += colour * (d.x * d.x - d.y * d.y);
    m_bins[BinOf(s.w)] += 1.0f;
    const int value = int(s.w * 1000.0f) + i % 7;
    m_least[i % 2] = std::min(m_least[i % 2], value);
    m_count += 1;
    spread[i % 3] += s.x;
    highest[(i / 7) % 2] = std::max(highest[(i / 7) % 2], s.y);
  }
  const float scale = 1.0f / float(std::max(n, 1));
  for (int k = 0; k < kMoments; ++k)
    m_moments[k] *= scale;
  for (int k = 0; k < 3; ++k)
    m_spread[k] = spread[k] * 3.0f * scale;
  m_highest[0] = highest[0];
  m_highest[1] = highest[1];
}
