#include "pointer_hits.h"

void Ground::Intersect(float3 org, float3 dir, uint32_t id, ShapeHit* hit) const
{
  if (dir.y >= 0.0f)
    return;
  const float t = (height - org.y) / dir.y;
  if (t > 0.0f && t < hit->t)
  {
    hit->t = t;
    hit->shape = id;
  }
}

void Ball::Intersect(float3 org, float3 dir, uint32_t id, ShapeHit* hit) const
{
  const float3 oc = org - to_float3(sphere);
  const float b = dot(oc, dir);
  const float c = dot(oc, oc) - sphere.w * sphere.w;
  const float disc = b * b - c;
  if (disc < 0.0f)
    return;
  const float t = -b - std::sqrt(disc);
  if (t > 0.0f && t < (*hit).t)
  {
    (*hit).t = t;
    hit[0].shape = id;
  }
}

PointerHits::PointerHits() : m_eye(0.0f, 1.0f, -4.0f)
{
  auto ground = std::make_shared<Ground>();
  auto near = std::make_shared<Ball>();
  near->sphere = float4(-0.6f, 0.8f, 0.0f, 0.8f);
  auto far = std::make_shared<Ball>();
  far->sphere = float4(0.9f, 1.2f, 2.0f, 1.2f);
  m_shapes = {ground, near, far};
}

void PointerHits::Trace(uint32_t n, const float4* a_dirs, float4* a_out) { kernel1D_Trace(n, a_dirs, a_out); }

void PointerHits::kernel1D_Trace(uint32_t n, const float4* a_dirs, float4* a_out)
{
  for (uint32_t i = 0; i < n; i++)
  {
    const float3 dir = normalize(to_float3(a_dirs[i]));
    ShapeHit hit;
    hit.t = 1e30f;
    hit.shape = 99u;
    for (uint32_t s = 0; s < uint32_t(m_shapes.size()); s++)
      m_shapes[s]->Intersect(m_eye, dir, s, &hit);
    const float area = hit.shape < 99u ? m_shapes[hit.shape]->Area() : 0.0f;
    a_out[i] = float4(hit.t < 1e30f ? hit.t : -1.0f, float(hit.shape), std::min(area, 100.0f), 0.0f);
  }
}
