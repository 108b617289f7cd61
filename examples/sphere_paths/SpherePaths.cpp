#include "SpherePaths.h"

#include <chrono>
#include <cmath>

using namespace LiteMath;

namespace {

// A well-mixed 32-bit hash (PCG output function): random numbers that are the same on every backend.
uint32_t Hash(uint32_t x)
{
  uint32_t state = x * 747796405u + 2891336453u;
  uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// A uniform number in [0, 1) from 24 random bits: exact in float, so every backend gets the same one.
float Random(uint32_t pixel, int sample, int bounce, uint32_t stream)
{
  uint32_t h = Hash(pixel ^ Hash(uint32_t(sample) * 9781u + uint32_t(bounce) * 6271u + stream));
  return float(h >> 8u) * (1.0f / 16777216.0f);
}

}  // namespace

SpherePaths::SpherePaths()
{
  // A Cornell-like scene: a big floor sphere, a diffuse and a mirror ball, a light above.
  m_spheres.push_back({float4(0.0f, -1000.0f, 0.0f, 1000.0f), float4(0.75f, 0.75f, 0.7f, 0.0f)});
  m_spheres.push_back({float4(-0.9f, 0.7f, 0.0f, 0.7f), float4(0.8f, 0.3f, 0.25f, 0.0f)});
  m_spheres.push_back({float4(0.9f, 0.6f, 0.4f, 0.6f), float4(0.95f, 0.95f, 0.95f, 1.0f)});
  m_spheres.push_back({float4(0.0f, 0.35f, 1.3f, 0.35f), float4(0.25f, 0.45f, 0.8f, 0.0f)});
  m_spheres.push_back({float4(0.0f, 4.0f, 0.5f, 1.2f), float4(6.0f, 5.5f, 5.0f, 2.0f)});
  m_cameraPos = float4(0.0f, 1.2f, 5.0f, 0.0f);
}

void SpherePaths::Render(uint32_t width, uint32_t height, int samples, float4* out_color)
{
  const auto start = std::chrono::steady_clock::now();
  for (uint32_t y = 0; y < height; y++)
    for (uint32_t x = 0; x < width; x++)
    {
      float4 rayPos, rayDir, throughput, color;
      SphereHit hit;
      for (int sample = 0; sample < samples; sample++)
      {
        kernel_InitEyeRay(x, y, width, height, sample, &rayPos, &rayDir, &throughput);
        for (int bounce = 0; bounce < m_maxDepth; bounce++)
        {
          kernel_RayTrace(x, y, &rayPos, &rayDir, &throughput, &hit);
          kernel_NextBounce(x, y, width, sample, bounce, &hit, &rayPos, &rayDir, &throughput, &color);
        }
      }
      kernel_Contribute(x, y, width, samples, &color, out_color);
    }
  m_timeMs = std::chrono::duration<float, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void SpherePaths::kernel_InitEyeRay(uint32_t tidX, uint32_t tidY, uint32_t width, uint32_t height, int sample, float4* rayPos, float4* rayDir,
                                    float4* throughput)
{
  // A jittered position inside the pixel, through a pinhole looking down -z.
  const uint32_t pixel = tidY * width + tidX;
  const float u = (float(tidX) + Random(pixel, sample, 0, 11u)) / float(width);
  const float v = (float(tidY) + Random(pixel, sample, 0, 12u)) / float(height);
  const float aspect = float(width) / float(height);
  const float3 dir = normalize(float3((2.0f * u - 1.0f) * m_tanHalfFov * aspect, (1.0f - 2.0f * v) * m_tanHalfFov - 0.15f, -1.0f));
  *rayPos = m_cameraPos;
  *rayDir = float4(dir.x, dir.y, dir.z, 0.0f);
  *throughput = float4(1.0f, 1.0f, 1.0f, 1.0f);  // w = 1: the path is alive
}

void SpherePaths::kernel_RayTrace(uint32_t tidX, uint32_t tidY, const float4* rayPos, const float4* rayDir, const float4* throughput, SphereHit* hit)
{
  (void)tidX;
  (void)tidY;
  hit->position.w = 0.0f;
  if (throughput->w == 0.0f)
    return;
  const float3 origin = to_float3(*rayPos), dir = to_float3(*rayDir);
  float nearest = 1e30f;
  for (int i = 0; i < int(m_spheres.size()); i++)
  {
    const float3 center = to_float3(m_spheres[i].centerRadius);
    const float radius = m_spheres[i].centerRadius.w;
    const float3 oc = origin - center;
    const float b = dot(oc, dir);
    const float c = dot(oc, oc) - radius * radius;
    const float disc = b * b - c;
    if (disc < 0.0f)
      continue;
    const float root = std::sqrt(disc);
    float t = -b - root;
    if (t < 1e-3f)
      t = -b + root;
    if (t >= 1e-3f && t < nearest)
    {
      nearest = t;
      hit->sphere = i;
    }
  }
  if (nearest == 1e30f)
    return;
  const float3 p = origin + dir * nearest;
  const float3 n = normalize(p - to_float3(m_spheres[hit->sphere].centerRadius));
  hit->position = float4(p.x, p.y, p.z, 1.0f);
  hit->normal = float4(n.x, n.y, n.z, 0.0f);
}

void SpherePaths::kernel_NextBounce(uint32_t tidX, uint32_t tidY, uint32_t width, int sample, int bounce, const SphereHit* hit, float4* rayPos,
                                    float4* rayDir, float4* throughput, float4* color)
{
  if (throughput->w == 0.0f)
    return;
  if (hit->position.w == 0.0f)  // left the scene: a dim sky
  {
    *color += *throughput * float4(0.1f, 0.12f, 0.16f, 0.0f);
    throughput->w = 0.0f;
    return;
  }
  const Sphere sphere = m_spheres[hit->sphere];
  const float material = sphere.color.w;
  if (material == 2.0f)  // a light ends the path
  {
    *color += *throughput * float4(sphere.color.x, sphere.color.y, sphere.color.z, 0.0f);
    throughput->w = 0.0f;
    return;
  }
  float3 n = to_float3(hit->normal);
  const float3 incoming = to_float3(*rayDir);
  if (dot(n, incoming) > 0.0f)
    n = -1.0f * n;
  float3 next;
  if (material == 1.0f)  // mirror
    next = incoming - 2.0f * dot(incoming, n) * n;
  else  // diffuse: a cosine-weighted direction around the normal
  {
    const uint32_t pixel = tidY * width + tidX;
    const float r1 = Random(pixel, sample, bounce + 1, 21u), r2 = Random(pixel, sample, bounce + 1, 22u);
    const float phi = 6.2831853f * r1, radius = std::sqrt(r2);
    const float3 helper = std::fabs(n.x) > 0.5f ? float3(0.0f, 1.0f, 0.0f) : float3(1.0f, 0.0f, 0.0f);
    const float3 tangent = normalize(cross(helper, n)), bitangent = cross(n, tangent);
    next = normalize(tangent * (radius * std::cos(phi)) + bitangent * (radius * std::sin(phi)) + n * std::sqrt(std::max(0.0f, 1.0f - r2)));
  }
  *throughput = *throughput * float4(sphere.color.x, sphere.color.y, sphere.color.z, 1.0f);
  *rayPos = float4(hit->position.x, hit->position.y, hit->position.z, 0.0f) + float4(n.x, n.y, n.z, 0.0f) * 1e-3f;
  *rayDir = float4(next.x, next.y, next.z, 0.0f);
}

void SpherePaths::kernel_Contribute(uint32_t tidX, uint32_t tidY, uint32_t width, int samples, const float4* color, float4* out_color)
{
  const float4 average = *color * (1.0f / float(samples));
  out_color[tidY * width + tidX] = float4(average.x, average.y, average.z, 1.0f);
}

void SpherePaths::GetExecutionTime(const char* a_funcName, float a_out[4])
{
  (void)a_funcName;
  for (int i = 0; i < 4; ++i)
    a_out[i] = m_timeMs;
}
