#include "SdfRender.h"

#include <algorithm>
#include <cmath>

void SdfRender::SetField(const litesdf::SdfSVS& svs, int newtonIterations)
{
  m_svs = svs;
  m_bvh = litesdf::BuildSdfBVH(m_svs);
  m_newtonIterations = newtonIterations;
}

void SdfRender::SetCamera(float3 eye, float3 target, float fovY)
{
  const float scale = std::tan(0.5f * fovY * 3.14159265f / 180.0f);
  m_eye = eye;
  m_forward = LiteMath::normalize(target - eye);
  m_right = scale * LiteMath::normalize(LiteMath::cross(float3(0.0f, 1.0f, 0.0f), m_forward));
  m_up = scale * LiteMath::normalize(LiteMath::cross(m_forward, m_right));
}

void SdfRender::Render(uint32_t* pixels, float* depth)
{
  kernel2D_Render(pixels, depth, m_width, m_height);
}

// The normal as a colour, dimmed where it faces away from a light over the camera's shoulder.
static uint32_t ShadeNormal(float3 n, float3 toLight)
{
  const float lit = 0.35f + 0.65f * std::max(LiteMath::dot(n, toLight), 0.0f);
  const float3 c = lit * (0.5f * n + float3(0.5f, 0.5f, 0.5f));
  const uint32_t r = uint32_t(std::min(std::max(c.x, 0.0f), 1.0f) * 255.0f + 0.5f);
  const uint32_t g = uint32_t(std::min(std::max(c.y, 0.0f), 1.0f) * 255.0f + 0.5f);
  const uint32_t b = uint32_t(std::min(std::max(c.z, 0.0f), 1.0f) * 255.0f + 0.5f);
  return r | (g << 8) | (b << 16) | 0xFF000000u;
}

void SdfRender::kernel2D_Render(uint32_t* pixels, float* depth, int width, int height)
{
  for (int y = 0; y < height; ++y)
  {
    for (int x = 0; x < width; ++x)
    {
      const float u = (float(x) + 0.5f) / float(width) * 2.0f - 1.0f;
      const float v = 1.0f - (float(y) + 0.5f) / float(height) * 2.0f;
      const float3 dir = LiteMath::normalize(m_forward + u * m_right + v * m_up);
      const litesdf::SdfHit hit = litesdf::TraceSVS(m_svs, m_bvh, m_eye, dir, 0.0f, 1e30f, m_newtonIterations);
      const float3 toLight = LiteMath::normalize(m_up - m_right - m_forward);
      pixels[y * width + x] = hit.t >= 0.0f ? ShadeNormal(hit.normal, toLight) : 0xFF332211u;
      depth[y * width + x] = hit.t;
    }
  }
}
