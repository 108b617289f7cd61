#include "ImageArguments.h"

#include <algorithm>

using LiteImage::Image2D;
using LiteMath::float2;
using LiteMath::float4;
using LiteMath::int2;

void ImageArguments::Blur(const Image4& in, Image4& out, float gain) { kernel2D_Blur(in, out, gain); }

void ImageArguments::Sample(const Image2D<float>& field, const Image4& albedo, int n, const float2* uv, float* heights, float4* colors)
{
  kernel1D_Sample(field, albedo, n, uv, heights, colors);
}

void ImageArguments::Accumulate(const Image4& frame, float alpha, float threshold, Image2D<uint32_t>& labels)
{
  kernel2D_Blend(frame, m_history, alpha);
  kernel2D_Threshold(m_history, labels, threshold);
}

void ImageArguments::Scale(Image2D<float>& img, float factor)
{
  for (int y = 0; y < int(img.height()); ++y)
    for (int x = 0; x < int(img.width()); ++x)
      kernel_Scale(x, y, img, factor);
}

void ImageArguments::kernel2D_Blur(const Image4& in, Image4& out, float gain)
{
  for (int y = 0; y < int(in.height()); ++y)
    for (int x = 0; x < int(in.width()); ++x)
    {
      float4 sum = float4(0.0f);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
        {
          const int cx = std::min(std::max(x + dx, 0), int(in.width()) - 1);
          const int cy = std::min(std::max(y + dy, 0), int(in.height()) - 1);
          sum += in[int2(cx, cy)];
        }
      out[int2(x, y)] = sum * (gain / 9.0f);
    }
}

void ImageArguments::kernel1D_Sample(const Image2D<float>& field, const Image4& albedo, int n, const float2* uv, float* heights, float4* colors)
{
  for (int i = 0; i < n; ++i)
  {
    heights[i] = field.sample(m_linear, uv[i]);
    colors[i] = albedo.sample(m_nearest, uv[i]) * float(albedo.width() * albedo.height());
  }
}

void ImageArguments::kernel2D_Blend(const Image4& frame, Image4& history, float alpha)
{
  for (int y = 0; y < int(history.height()); ++y)
    for (int x = 0; x < int(history.width()); ++x)
      history.set(x, y, history.at(x, y) * (1.0f - alpha) + frame[int2(x, y)] * alpha);
}

void ImageArguments::kernel2D_Threshold(const Image4& image, Image2D<uint32_t>& labels, float threshold)
{
  for (int y = 0; y < int(image.height()); ++y)
    for (int x = 0; x < int(image.width()); ++x)
    {
      const float4 c = image[int2(x, y)];
      labels[int2(x, y)] = 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z > threshold ? 1u : 0u;
    }
}

void ImageArguments::kernel_Scale(int tidX, int tidY, Image2D<float>& img, float factor)
{
  img[int2(tidX, tidY)] = img[int2(tidX, tidY)] * factor;
}
