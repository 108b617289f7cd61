#include "Bloom.h"

#include <cmath>

using namespace LiteMath;

Bloom::Bloom(int width, int height, int radius, float sigma) : m_radius(radius)
{
  m_weights.resize(2 * radius + 1);
  float sum = 0.0f;
  for (int k = -radius; k <= radius; ++k)
    sum += (m_weights[k + radius] = std::exp(-0.5f * float(k * k) / (sigma * sigma)));
  for (float& w : m_weights)
    w /= sum;
  m_bright.resize(size_t(width) * height);
  m_blurred.resize(size_t(width) * height);
}

void Bloom::Run(int width, int height, const float4* in, float4* out)
{
  kernel2D_ExtractBright(width, height, in, m_bright.data());
  kernel2D_BlurX(width, height, m_bright.data(), m_blurred.data());
  kernel2D_BlurYAndAdd(width, height, m_blurred.data(), in, out);
}

void Bloom::kernel2D_ExtractBright(int width, int height, const float4* in, float4* bright)
{
  for (int y = 0; y < height; y++)
    for (int x = 0; x < width; x++)
    {
      const float4 c = in[y * width + x];
      const float excess = std::max(Luminance(c) - m_threshold, 0.0f);
      bright[y * width + x] = c * (excess / std::max(Luminance(c), 1e-6f));
    }
}

void Bloom::kernel2D_BlurX(int width, int height, const float4* src, float4* dst)
{
  for (int y = 0; y < height; y++)
    for (int x = 0; x < width; x++)
    {
      float4 sum = float4(0.0f);
      for (int k = -m_radius; k <= m_radius; k++)
      {
        const int xk = clamp(x + k, 0, width - 1);
        sum += src[y * width + xk] * m_weights[k + m_radius];
      }
      dst[y * width + x] = sum;
    }
}

void Bloom::kernel2D_BlurYAndAdd(int width, int height, const float4* src, const float4* in, float4* out)
{
  for (int y = 0; y < height; y++)
    for (int x = 0; x < width; x++)
    {
      float4 sum = float4(0.0f);
      for (int k = -m_radius; k <= m_radius; k++)
      {
        const int yk = clamp(y + k, 0, height - 1);
        sum += src[yk * width + x] * m_weights[k + m_radius];
      }
      out[y * width + x] = in[y * width + x] + sum * m_strength;
    }
}
