#include "box_blur.h"

#include <algorithm>

BoxBlur::BoxBlur(int w, int h) : m_image(w, h)
{
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      m_image[int2(x, y)] = float4(float(x % 7), float(y % 5), float((x * y) % 3), 1.0f);
}

void BoxBlur::Blur(int w, int h, float4* a_out) { kernel2D_Blur(w, h, a_out); }

void BoxBlur::kernel2D_Blur(int w, int h, float4* a_out)
{
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
    {
      float4 sum(0.0f);
      for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++)
          sum += m_image[int2(std::clamp(x + dx, 0, w - 1), std::clamp(y + dy, 0, h - 1))];
      a_out[y * w + x] = sum / 9.0f;
    }
}
