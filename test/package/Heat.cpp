#include "Heat.h"

void Heat::Diffuse(int steps, float* grid)
{
  for (int s = 0; s < steps; ++s)  // a host loop around kernels stays a host loop
  {
    kernel2D_Step(m_width, m_height, grid, m_next.data());
    m_total = 0.0f;
    kernel1D_CopyBack(m_width * m_height, grid);
  }
}

void Heat::kernel2D_Step(int w, int h, const float* src, float* dst)
{
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
    {
      const float c = src[y * w + x];
      const float l = x > 0 ? src[y * w + x - 1] : c, r = x + 1 < w ? src[y * w + x + 1] : c;
      const float d = y > 0 ? src[(y - 1) * w + x] : c, u = y + 1 < h ? src[(y + 1) * w + x] : c;
      dst[y * w + x] = c + m_rate * (l + r + d + u - 4.0f * c);
    }
}

void Heat::kernel1D_CopyBack(int n, float* grid)
{
  for (int i = 0; i < n; i++)
  {
    grid[i] = m_next[i];
    m_total += m_next[i];
  }
}
