#include "SdfRender.h"

#include <algorithm>
#include <cmath>

namespace {

constexpr uint32_t kMissId = 0xFFFFFFFFu;

// A 32-bit integer hash (Wellons' lowbias32), for per-pixel random numbers.
uint32_t Hash(uint32_t x)
{
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

float UnitFloat(uint32_t h) { return float(h >> 8) * (1.0f / 16777216.0f); }

uint32_t PackRGBA8(float3 c)
{
  const uint32_t r = uint32_t(std::min(std::max(c.x, 0.0f), 1.0f) * 255.0f + 0.5f);
  const uint32_t g = uint32_t(std::min(std::max(c.y, 0.0f), 1.0f) * 255.0f + 0.5f);
  const uint32_t b = uint32_t(std::min(std::max(c.z, 0.0f), 1.0f) * 255.0f + 0.5f);
  return r | (g << 8) | (b << 16) | 0xFF000000u;
}

}  // namespace

void SdfRender::SetCamera(float3 eye, float3 target, float fovY)
{
  const float scale = std::tan(0.5f * fovY * 3.14159265f / 180.0f);
  m_eye = eye;
  m_forward = LiteMath::normalize(target - eye);
  m_right = scale * LiteMath::normalize(LiteMath::cross(float3(0.0f, 1.0f, 0.0f), m_forward));
  m_up = scale * LiteMath::normalize(LiteMath::cross(m_forward, m_right));
}

void SdfRender::SetOcclusion(int samples, float distance)
{
  m_aoSamples = samples;
  m_aoDistance = distance;
}

void SdfRender::Render(uint32_t* pixels, float* depth) { kernel2D_Render(pixels, depth, m_width, m_height); }

float3 SdfRender::Shade(const CRT_Hit& hit, float3 org, float3 dir, uint32_t pixel) const
{
  // The field's normal (object space: the example places its fields unrotated).
  float3 normal = float3(hit.coords[0], hit.coords[1], hit.coords[2]);
  if (LiteMath::dot(normal, normal) == 0.0f)
    normal = dir * -1.0f;
  const float3 base = normal * 0.35f + float3(0.6f, 0.6f, 0.6f);
  const float facing = std::max(-LiteMath::dot(normal, dir), 0.0f);

  // Ambient occlusion: cosine-weighted rays around the normal, from outside the surface (a ray that
  // starts inside a field hits at once).
  float open = 1.0f;
  if (m_aoSamples > 0)
  {
    const float3 start = org + dir * hit.t + normal * (0.05f * m_aoDistance);
    const float sign = normal.z >= 0.0f ? 1.0f : -1.0f;  // an orthonormal basis (Duff et al. 2017)
    const float k = -1.0f / (sign + normal.z);
    const float m = normal.x * normal.y * k;
    const float3 t1 = float3(1.0f + sign * normal.x * normal.x * k, sign * m, -sign * normal.x);
    const float3 t2 = float3(m, sign + normal.y * normal.y * k, -normal.y);
    int blocked = 0;
    for (int s = 0; s < m_aoSamples; ++s)
    {
      const uint32_t h = Hash(pixel * 16u + uint32_t(s));
      const float r = std::sqrt(UnitFloat(h));
      const float phi = 6.28318531f * UnitFloat(Hash(h));
      const float3 d = t1 * (r * std::cos(phi)) + t2 * (r * std::sin(phi)) + normal * std::sqrt(std::max(0.0f, 1.0f - r * r));
      if (m_pAccelStruct->RayQuery_AnyHit(float4(start.x, start.y, start.z, 0.0f), float4(d.x, d.y, d.z, m_aoDistance)))
        blocked = blocked + 1;
    }
    open = 1.0f - float(blocked) / float(m_aoSamples);
  }
  return base * ((0.25f + 0.75f * facing) * (0.3f + 0.7f * open));
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
      const CRT_Hit hit = m_pAccelStruct->RayQuery_NearestHit(float4(m_eye.x, m_eye.y, m_eye.z, 0.0f), float4(dir.x, dir.y, dir.z, 1e30f));
      const uint32_t pixel = uint32_t(y * width + x);
      const bool found = hit.primId != kMissId;
      pixels[pixel] = found ? PackRGBA8(Shade(hit, m_eye, dir, pixel)) : 0xFF332211u;
      depth[pixel] = found ? hit.t : -1.0f;
    }
  }
}
