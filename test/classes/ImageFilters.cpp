#include "ImageFilters.h"

#include <algorithm>

using LiteMath::float2;
using LiteMath::float4;
using LiteMath::int2;

void ImageFilters::Blur(float threshold) { kernel2D_Blur(threshold); }

void ImageFilters::Sample(int n, const float2* uv, float4* nearest, float4* linear, float* heights)
{
  kernel1D_Sample(n, uv, nearest, linear, heights);
}

void ImageFilters::Accumulate(float weight) { kernel2D_Accumulate(weight); }

void ImageFilters::Double()
{
  for (int y = 0; y < int(m_accumulated.height()); ++y)
    for (int x = 0; x < int(m_accumulated.width()); ++x)
      kernel_Double(x, y);
}

void ImageFilters::kernel_Double(int tidX, int tidY)
{
  const float2 centre = float2((float(tidX) + 0.5f) / float(m_accumulated.width()), (float(tidY) + 0.5f) / float(m_accumulated.height()));
  m_accumulated[int2(tidX, tidY)] = 2.0f * m_accumulated.sample(m_nearest, centre);
}

float4 ImageFilters::SourceTexel(int x, int y) const
{
  const int cx = std::min(std::max(x, 0), int(m_source.width()) - 1);
  const int cy = std::min(std::max(y, 0), int(m_source.height()) - 1);
  return m_source[int2(cx, cy)];
}

void ImageFilters::kernel2D_Blur(float threshold)
{
  for (int y = 0; y < int(m_source.height()); ++y)
    for (int x = 0; x < int(m_source.width()); ++x)
    {
      float4 sum = float4(0.0f);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          sum += SourceTexel(x + dx, y + dy);
      const float4 blurred = sum / 9.0f;
      m_blurred[int2(x, y)] = blurred;
      const float luminance = 0.2126f * blurred.x + 0.7152f * blurred.y + 0.0722f * blurred.z;
      m_luminance.set(x, y, luminance);
      m_labels[int2(x, y)] = luminance > threshold ? 1u : 0u;
    }
}

void ImageFilters::kernel1D_Sample(int n, const float2* uv, float4* nearest, float4* linear, float* heights)
{
  for (int i = 0; i < n; ++i)
  {
    nearest[i] = m_source.sample(m_nearest, uv[i]);
    linear[i] = m_source.sample(m_linear, uv[i]);
    heights[i] = m_heights.sample(m_heightSampler, uv[i]);
  }
}

void ImageFilters::kernel2D_Accumulate(float weight)
{
  for (int y = 0; y < int(m_accumulated.height()); ++y)
    for (int x = 0; x < int(m_accumulated.width()); ++x)
    {
      m_accumulated[int2(x, y)] += weight * m_source.at(x, y);
      m_counts[int2(x, y)] += 1u;
    }
}
