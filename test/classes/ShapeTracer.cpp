#include "ShapeTracer.h"

#include <cmath>

using LiteMath::float3;
using LiteMath::float4;

namespace
{
float3 Xyz(float4 v) { return float3(v.x, v.y, v.z); }

// Records a hit at t with normal n when it is nearer than the hit so far.
void Record(float t, float4 posAndNear, uint32_t shapeId, float3 n, ShapeHit& hit)
{
  if (t >= posAndNear.w && t < hit.t)
  {
    hit.t = t;
    hit.shape = shapeId;
    hit.nx = n.x;
    hit.ny = n.y;
    hit.nz = n.z;
  }
}

// Where the ray enters (tmin) and leaves (tmax) the slabs of the box [lo, hi], per axis.
void SlabTimes(float4 posAndNear, float4 dirAndFar, float4 lo, float4 hi, float3& tmin, float3& tmax)
{
  const float3 inv = float3(1.0f / dirAndFar.x, 1.0f / dirAndFar.y, 1.0f / dirAndFar.z);
  const float3 t0 = (Xyz(lo) - Xyz(posAndNear)) * inv, t1 = (Xyz(hi) - Xyz(posAndNear)) * inv;
  tmin = LiteMath::min(t0, t1);
  tmax = LiteMath::max(t0, t1);
}

// Whether the ray meets the box [lo, hi] within [near, far] (the slab test).
bool HitsBox(float4 posAndNear, float4 dirAndFar, float far, float4 lo, float4 hi)
{
  float3 tmin, tmax;
  SlabTimes(posAndNear, dirAndFar, lo, hi, tmin, tmax);
  const float enter = std::max(std::max(tmin.x, tmin.y), std::max(tmin.z, posAndNear.w));
  const float leave = std::min(std::min(tmax.x, tmax.y), std::min(tmax.z, far));
  return enter <= leave;
}
}  // namespace

void Sphere::Intersect(float4 posAndNear, float4 dirAndFar, uint32_t shapeId, ShapeHit& hit) const
{
  const float3 oc = Xyz(posAndNear) - Xyz(centerAndRadius), d = Xyz(dirAndFar);
  const float b = LiteMath::dot(oc, d), c = LiteMath::dot(oc, oc) - centerAndRadius.w * centerAndRadius.w;
  const float disc = b * b - c;  // d has unit length
  if (disc < 0.0f)
    return;
  const float root = std::sqrt(disc);
  const float t = -b - root >= posAndNear.w ? -b - root : -b + root;
  const float3 p = Xyz(posAndNear) + t * d;
  Record(t, posAndNear, shapeId, (p - Xyz(centerAndRadius)) / centerAndRadius.w, hit);
}

float4 Sphere::BoxMin() const { return centerAndRadius - float4(centerAndRadius.w, centerAndRadius.w, centerAndRadius.w, centerAndRadius.w); }
float4 Sphere::BoxMax() const { return centerAndRadius + float4(centerAndRadius.w, centerAndRadius.w, centerAndRadius.w, centerAndRadius.w); }

void Box::Intersect(float4 posAndNear, float4 dirAndFar, uint32_t shapeId, ShapeHit& hit) const
{
  float3 tmin, tmax;
  SlabTimes(posAndNear, dirAndFar, boxMin, boxMax, tmin, tmax);
  const float enter = std::max(std::max(tmin.x, tmin.y), tmin.z), leave = std::min(std::min(tmax.x, tmax.y), tmax.z);
  if (enter > leave)
    return;
  // The face the ray enters through: the axis whose slab it enters last.
  float3 n = float3(0.0f, 0.0f, 0.0f);
  if (enter == tmin.x)
    n.x = dirAndFar.x > 0.0f ? -1.0f : 1.0f;
  else if (enter == tmin.y)
    n.y = dirAndFar.y > 0.0f ? -1.0f : 1.0f;
  else
    n.z = dirAndFar.z > 0.0f ? -1.0f : 1.0f;
  Record(enter, posAndNear, shapeId, n, hit);
}

void Disc::Intersect(float4 posAndNear, float4 dirAndFar, uint32_t shapeId, ShapeHit& hit) const
{
  const float3 n = Xyz(normal);
  const float denom = LiteMath::dot(n, Xyz(dirAndFar));
  if (std::fabs(denom) < 1e-8f)
    return;
  const float t = LiteMath::dot(Xyz(center) - Xyz(posAndNear), n) / denom;
  const float3 p = Xyz(posAndNear) + t * Xyz(dirAndFar) - Xyz(center);
  if (LiteMath::dot(p, p) > radius * radius)
    return;
  Record(t, posAndNear, shapeId, denom < 0.0f ? n : -1.0f * n, hit);
}

float4 Disc::BoxMin() const { return center - float4(radius, radius, radius, 0.0f); }
float4 Disc::BoxMax() const { return center + float4(radius, radius, radius, 0.0f); }

void ShapeScene::Add(std::shared_ptr<IShape> shape)
{
  m_boxes.push_back(shape->BoxMin());
  m_boxes.push_back(shape->BoxMax());
  m_shapes.push_back(std::move(shape));
}

void ShapeScene::AddLight(std::shared_ptr<IShape> light)
{
  m_lightBoxes.push_back(light->BoxMin());
  m_lightBoxes.push_back(light->BoxMax());
  m_lights.push_back(std::move(light));
}

ShapeHit ShapeScene::Trace(float4 posAndNear, float4 dirAndFar)
{
  ShapeHit hit;
  hit.t = dirAndFar.w;
  hit.shape = ~0u;
  hit.nx = hit.ny = hit.nz = 0.0f;
  hit.pad0 = hit.pad1 = hit.pad2 = 0.0f;
  const uint32_t count = uint32_t(m_boxes.size() / 2);
  for (uint32_t i = 0; i < count; ++i)
    if (HitsBox(posAndNear, dirAndFar, hit.t, m_boxes[2 * i], m_boxes[2 * i + 1]))  // a leaf: its primitive's own test
      m_shapes[i]->Intersect(posAndNear, dirAndFar, i, hit);
  // The lights, nearer than the nearest shape, into a hit of their own.
  ShapeHit light = hit;
  light.shape = ~0u;
  for (uint32_t i = 0; i < m_lights.size(); ++i)
    if (HitsBox(posAndNear, dirAndFar, light.t, m_lightBoxes[2 * i], m_lightBoxes[2 * i + 1]))
      m_lights[i]->Intersect(posAndNear, dirAndFar, i, light);
  if (light.shape != ~0u)
  {
    hit = light;
    hit.shape = kLightHit + light.shape;
  }
  return hit;
}

void ShapeTracer::Trace(int n, const float4* origins, const float4* dirs, float far, ShapeHit* hits) { kernel1D_Trace(n, origins, dirs, far, hits); }

void ShapeTracer::kernel1D_Trace(int n, const float4* origins, const float4* dirs, float far, ShapeHit* hits)
{
  for (int i = 0; i < n; ++i)
  {
    const float4 o = origins[i], d = dirs[i];
    hits[i] = m_scene->Trace(float4(o.x, o.y, o.z, 0.0f), float4(d.x, d.y, d.z, far));
  }
}
