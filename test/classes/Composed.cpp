#include "Composed.h"

#include <algorithm>
#include <cmath>

using LiteMath::float3;

float SdfSpheres::Distance(float3 p)
{
  float d = 1e30f;
  for (int i = 0; i < m_count; ++i)
  {
    const float s = LiteMath::length(p - LiteMath::to_float3(m_spheres[i])) - m_spheres[i].w;
    if (m_smoothing <= 0.0f)
    {
      d = std::min(d, s);
      continue;
    }
    const float h = std::max(m_smoothing - std::fabs(d - s), 0.0f) / m_smoothing;
    d = std::min(d, s) - h * h * m_smoothing * 0.25f;
  }
  return d;
}

void SphereTracer::Trace(int n, const LiteMath::float4* origins, float* depth) { kernel1D_Trace(n, origins, depth); }

void SphereTracer::kernel1D_Trace(int n, const LiteMath::float4* origins, float* depth)
{
  for (int i = 0; i < n; i++)
  {
    const float3 org = LiteMath::to_float3(origins[i]);
    float t = 0.0f;
    float result = -1.0f;
    for (int step = 0; step < 128 && t < 20.0f; ++step)
    {
      const float d = m_shape->Distance(org + float3(0.0f, 0.0f, -t));
      if (d < 1e-4f)
      {
        result = t;
        break;
      }
      t += d;
    }
    depth[i] = result;
  }
}
