#include "ray_caster.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace
{
// RGBA8, red in the low byte.
uint32_t PackColor(float3 c)
{
  const uint32_t r = uint32_t(clamp(c.x, 0.0f, 1.0f) * 255.0f);
  const uint32_t g = uint32_t(clamp(c.y, 0.0f, 1.0f) * 255.0f);
  const uint32_t b = uint32_t(clamp(c.z, 0.0f, 1.0f) * 255.0f);
  return r | (g << 8) | (b << 16) | 0xFF000000u;
}
} // namespace

// A colour per triangle, from its id.
static float3 Palette(uint32_t id)
{
  const float h = float((id * 2654435761u) >> 8) / 16777216.0f;
  return float3(0.5f + 0.5f * std::cos(6.2831853f * h), 0.5f + 0.5f * std::cos(6.2831853f * (h + 0.33f)),
                0.5f + 0.5f * std::cos(6.2831853f * (h + 0.67f)));
}

RayCaster::RayCaster(int a_width, int a_height) : m_width(a_width), m_height(a_height)
{
  m_hitDepths.resize(size_t(a_width) * size_t(a_height));
  m_rowHits.resize(size_t(a_height));
  m_rowOffsets.resize(size_t(a_height));
  m_shades.push_back(std::make_shared<FlatShade>());
  m_shades.push_back(std::make_shared<StripeShade>());
}

void RayCaster::SetCamera(float3 a_eye, float a_fovDegrees)
{
  m_eye = to_float4(a_eye, 0.0f);
  m_tanHalfFov = std::tan(0.5f * a_fovDegrees * float(M_PI) / 180.0f);
}

float3 RayCaster::EyeRayDir(int x, int y) const
{
  const float u = (2.0f * (float(x) + 0.5f) / float(m_width) - 1.0f) * m_tanHalfFov * float(m_width) / float(m_height);
  const float v = (1.0f - 2.0f * (float(y) + 0.5f) / float(m_height)) * m_tanHalfFov;
  return normalize(float3(u, v, -1.0f));
}

void RayCaster::Render(uint32_t* a_color, float* a_depth)
{
  kernel2D_Render(a_color, a_depth, m_width, m_height);
  kernel1D_CollectHits(a_depth, m_width * m_height);
}

void RayCaster::kernel2D_Render(uint32_t* a_color, float* a_depth, int a_width, int a_height)
{
  m_hitCount = 0;
  m_maxDepth = 0.0f;
  float depthSum = 0.0f;
  for (int y = 0; y < a_height; y++)
  {
    for (int x = 0; x < a_width; x++)
    {
      const float3 dir = EyeRayDir(x, y);
      const CRT_Hit hit = m_pAccelStruct->RayQuery_NearestHit(m_eye, to_float4(dir, 100.0f));
      if (hit.primId == 0xFFFFFFFFu)
      {
        a_color[y * a_width + x] = PackColor(float3(0.1f, 0.1f, 0.2f));
        a_depth[y * a_width + x] = 0.0f;
        continue;
      }
      const float3 base = m_shades[hit.instId % m_shades.size()]->Color(dir, hit.primId);
      a_color[y * a_width + x] = PackColor(0.8f * base + 0.2f * Palette(hit.primId));
      a_depth[y * a_width + x] = hit.t;
      m_hitCount += 1;
      depthSum += hit.t;
      m_maxDepth = std::max(m_maxDepth, hit.t);
    }
  }
  m_meanDepth = m_hitCount > 0 ? depthSum / float(m_hitCount) : 0.0f;
}

void RayCaster::kernel1D_CollectHits(const float* a_depth, int a_count)
{
  m_hitDepths.clear();
  for (int i = 0; i < a_count; i++)
    if (a_depth[i] > 0.0f)
      m_hitDepths.push_back(a_depth[i]);
}

void RayCaster::SortedDepths(float* a_sorted, uint32_t* a_count)
{
  std::sort(m_hitDepths.begin(), m_hitDepths.end());
  kernel1D_CopySorted(a_sorted, a_count);
}

void RayCaster::kernel1D_CopySorted(float* a_sorted, uint32_t* a_count)
{
  for (uint32_t i = 0; i < m_hitDepths.size(); i++)
    a_sorted[i] = m_hitDepths[i];
  a_count[0] = uint32_t(m_hitDepths.size());
}

void RayCaster::RowOffsets(const float* a_depth, uint32_t* a_offsets)
{
  kernel1D_CountRows(a_depth, m_width, m_height);
  std::exclusive_scan(m_rowHits.begin(), m_rowHits.end(), m_rowOffsets.begin(), 0u);
  kernel1D_CopyOffsets(a_offsets, m_height);
}

void RayCaster::kernel1D_CountRows(const float* a_depth, int a_width, int a_height)
{
  for (int y = 0; y < a_height; y++)
  {
    uint32_t hits = 0;
    for (int x = 0; x < a_width; x++)
      hits += a_depth[y * a_width + x] > 0.0f ? 1u : 0u;
    m_rowHits[y] = hits;
  }
}

void RayCaster::kernel1D_CopyOffsets(uint32_t* a_offsets, int a_height)
{
  for (int y = 0; y < a_height; y++)
    a_offsets[y] = m_rowOffsets[y];
}
