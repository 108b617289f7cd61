#include "PrimaryRays.h"

#include <cmath>
#include <stdexcept>

using LiteMath::float4x4;

namespace {

constexpr uint32_t kMissId = 0xFFFFFFFFu;

// Integer hash (2 multiply-xorshift rounds): the same bits on every backend, unlike a float RNG.
uint32_t Hash(uint32_t x)
{
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// A uniform number in [0, 1) from 24 bits of a hash.
float UnitFloat(uint32_t h) { return float(h >> 8) * (1.0f / 16777216.0f); }

}  // namespace

PrimaryRays::PrimaryRays(int width, int height) : m_width(width), m_height(height)
{
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("PrimaryRays: image size must be positive");
}

void PrimaryRays::SetScene(std::shared_ptr<ISceneObject> scene, const std::vector<float>& positions,
                           const std::vector<uint32_t>& indices)
{
  if (positions.size() % 3 != 0 || indices.size() % 3 != 0)
    throw std::invalid_argument("PrimaryRays::SetScene: positions and indices must come in threes");
  m_pAccelStruct = std::move(scene);
  m_vertices.clear();
  for (size_t i = 0; i < positions.size(); i += 3)
    m_vertices.push_back(float4(positions[i], positions[i + 1], positions[i + 2], 0.0f));
  for (uint32_t index : indices)
    if (index >= m_vertices.size())
      throw std::invalid_argument("PrimaryRays::SetScene: index out of range");
  m_indices = indices;
}

void PrimaryRays::SetCamera(float3 eye, float3 target, float3 up, float fovY)
{
  const float3 forward = LiteMath::normalize(target - eye);
  const float3 right = LiteMath::normalize(LiteMath::cross(forward, up));
  const float3 trueUp = LiteMath::cross(right, forward);
  const float halfHeight = std::tan(0.5f * fovY * 3.14159265f / 180.0f);
  const float halfWidth = halfHeight * float(m_width) / float(m_height);
  m_eye = float4(eye.x, eye.y, eye.z, 0.0f);
  m_forward = float4(forward.x, forward.y, forward.z, 0.0f);
  m_right = float4(right.x, right.y, right.z, 0.0f) * halfWidth;
  m_up = float4(trueUp.x, trueUp.y, trueUp.z, 0.0f) * halfHeight;
}

void PrimaryRays::SetOcclusion(int samples, float distance)
{
  m_aoSamples = std::max(samples, 0);
  m_aoDistance = distance;
}

void PrimaryRays::Render(uint32_t* pixels) { kernel2D_Render(pixels, m_width, m_height); }

void PrimaryRays::CastRays(const float4* posAndNear, const float4* dirAndFar, CRT_Hit* hits, int n)
{
  kernel1D_CastRays(posAndNear, dirAndFar, hits, n);
}

void PrimaryRays::kernel1D_CastRays(const float4* posAndNear, const float4* dirAndFar, CRT_Hit* hits, int n)
{
  for (int i = 0; i < n; ++i)
    hits[i] = m_pAccelStruct->RayQuery_NearestHit(posAndNear[i], dirAndFar[i]);
}

void PrimaryRays::kernel2D_Render(uint32_t* pixels, int width, int height)
{
  for (int y = 0; y < height; ++y)
  {
    for (int x = 0; x < width; ++x)
    {
      const float sx = 2.0f * (float(x) + 0.5f) / float(width) - 1.0f;
      const float sy = 1.0f - 2.0f * (float(y) + 0.5f) / float(height);
      const float4 dir = m_forward + m_right * sx + m_up * sy;
      const CRT_Hit hit = m_pAccelStruct->RayQuery_NearestHit(m_eye, float4(dir.x, dir.y, dir.z, kCameraFar));
      const uint32_t pixel = uint32_t(y * width + x);
      pixels[pixel] = PackRGBA8(Shade(hit, to_float3(m_eye), to_float3(dir), pixel));
    }
  }
}

float3 PrimaryRays::Shade(const CRT_Hit& hit, float3 org, float3 dir, uint32_t pixel) const
{
  if (hit.primId == kMissId)
    return float3(0.6f, 0.65f, 0.7f);  // background
  const uint32_t tri = hit.primId;
  const float3 a = to_float3(m_vertices[m_indices[3 * tri]]);
  const float3 b = to_float3(m_vertices[m_indices[3 * tri + 1]]);
  const float3 c = to_float3(m_vertices[m_indices[3 * tri + 2]]);
  float3 normal = LiteMath::normalize(LiteMath::cross(b - a, c - a));
  if (LiteMath::dot(normal, dir) > 0.0f)
    normal = normal * -1.0f;  // the side the ray sees
  const float3 base = normal * 0.35f + float3(0.6f, 0.6f, 0.6f);
  const float facing = -LiteMath::dot(normal, LiteMath::normalize(dir));

  // Ambient occlusion: cosine-weighted rays around the normal, from just above the surface.
  float open = 1.0f;
  if (m_aoSamples > 0)
  {
    const float3 p = org + dir * hit.t;
    const float3 start = p + normal * (1e-3f * m_aoDistance + 1e-6f * LiteMath::length(p));
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
