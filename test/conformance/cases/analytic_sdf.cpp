#include "analytic_sdf.h"

#include <algorithm>

using LiteMath::float3;

namespace {
constexpr int kMaxSteps = 160;
constexpr float kFar = 8.0f;
}  // namespace

FractalView::FractalView(int width, int height) : m_width(width), m_height(height)
{
  m_eye = float3(0.0f, 0.5f, 3.0f);
  m_forward = LiteMath::normalize(float3(0.0f) - m_eye);
  m_right = LiteMath::normalize(LiteMath::cross(m_forward, float3(0.0f, 1.0f, 0.0f)));
  m_up = LiteMath::cross(m_right, m_forward);
}

void FractalView::Render(float* depth)
{
  const float pixels = float(m_width * m_height);
  m_coverage = 0.0f;
  kernel2D_Render(depth, m_width, m_height);
  m_coverage = m_coverage / pixels;  // after the kernel: the fraction of pixels hit
}

float FractalView::Scene(float3 p) const
{
  float d = kFar;
  for (size_t k = 0; k < m_shapes.size(); ++k)
    d = std::min(d, m_shapes[k]->Distance(p));
  return d;
}

void FractalView::kernel2D_Render(float* depth, int width, int height)
{
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
    {
      const float u = (2.0f * (float(x) + 0.5f) / float(width) - 1.0f) * float(width) / float(height);
      const float v = 1.0f - 2.0f * (float(y) + 0.5f) / float(height);
      const float3 dir = LiteMath::normalize(m_forward * 1.5f + m_right * u + m_up * v);
      float t = 0.0f;
      bool hit = false;
      for (int step = 0; step < kMaxSteps; ++step)
      {
        const float d = Scene(m_eye + dir * t);
        if (d < 1e-4f * (1.0f + t))
        {
          hit = true;
          break;
        }
        t += d;
        if (t > kFar)
          break;
      }
      depth[y * width + x] = hit ? t : -1.0f;
      if (hit)
        m_coverage += 1.0f;
    }
}
