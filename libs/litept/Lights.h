// The path tracer's light sources (libs/litept): a second virtual hierarchy. A light draws a point
// (or a direction) as seen from a shaded point, with the radiance arriving from it and the density
// of that choice in solid angle, and gives that density for a direction a BSDF drew, so that the two
// strategies combine by multiple importance sampling. The environment map is the integrator's own
// (it needs the map and its distribution, which live in the integrator's vectors).
//
//   TriangleLight     an emissive triangle, sampled uniformly by area (front side only unless
//                     two-sided); the scene's emissive meshes become one per triangle.
//   SphereLight       a sphere of uniform radiance, sampled by the cone of directions it fills.
//   RectLight         a rectangle of uniform radiance, sampled uniformly by area.
//                     Spheres and rectangles are not in the scene's geometry: the integrator
//                     meets them itself (Intersect), so that BSDF rays find them too.
//   PointLight        glTF KHR_lights_punctual "point": an intensity, falling off with 1 / d^2.
//   SpotLight         "spot": a point light within a cone, with glTF's smooth edge.
//   DirectionalLight  "directional": parallel light of a given irradiance.
#pragma once
#include "Sampling.h"

#include <cstdint>

namespace litept {

// A light's sample as seen from a point.
struct LightSample
{
  float4 dirDist;      // xyz: unit direction from the point to the light; w: the distance (1e30 for light from infinity)
  float4 radiancePdf;  // xyz: radiance arriving (for point lights: intensity / d^2); w: density in solid angle (1 for a delta light), 0 if none
  uint32_t delta;      // 1 when no BSDF ray can find this light (point, spot, directional)
};

inline LightSample NoLight()
{
  LightSample s;
  s.dirDist = float4(0.0f, 0.0f, 1.0f, 0.0f);
  s.radiancePdf = float4(0.0f);
  s.delta = 1u;
  return s;
}

struct ILight
{
  virtual ~ILight() = default;
  // A sample from two uniform numbers, as seen from p.
  virtual LightSample Sample(float3 p, float2 u) const = 0;
  // The density (solid angle) with which Sample, from p, picks the point at p + dir * dist, which a
  // BSDF ray found on this light. 0 for delta lights.
  virtual float Pdf(float3 p, float3 dir, float dist) const
  {
    (void)p, (void)dir, (void)dist;
    return 0.0f;
  }
  // For a light with a shape of its own (not in the scene's geometry): the distance along the unit
  // dir from p to where a ray meets it, 1e30 if it does not; and the radiance it sends back along
  // -dir from there. Lights that are geometry, or points, meet nothing here.
  virtual float Intersect(float3 p, float3 dir) const
  {
    (void)p, (void)dir;
    return 1e30f;
  }
  virtual float3 RadianceTowards(float3 dir) const
  {
    (void)dir;
    return float3(0.0f);
  }
  // Roughly the power it emits (the weight for picking it among the scene's lights); host side.
  virtual float Power() const = 0;
};

// ---------------------------------------------------------------- lights with an area

// The point q of a flat light drawn uniformly by area (normal: its facing side, any length; area:
// its area), as seen from p, with the density of that choice in solid angle. None from behind a
// one-sided light (radiance.w == 0).
inline LightSample FromAreaPoint(float3 p, float3 q, float3 normal, float area, float4 radiance)
{
  const float3 d = q - p;
  const float dist2 = LiteMath::dot(d, d);
  const float normalLength = LiteMath::length(normal);
  if (dist2 <= 0.0f || area <= 0.0f || normalLength <= 0.0f)
    return NoLight();
  const float dist = std::sqrt(dist2);
  const float3 dir = d * (1.0f / dist);
  const float cosL = -LiteMath::dot(normal, dir) / normalLength;
  if (cosL <= 0.0f && (radiance.w == 0.0f || cosL == 0.0f))
    return NoLight();
  LightSample s;
  s.dirDist = to_float4(dir, dist);
  s.radiancePdf = to_float4(to_float3(radiance), dist2 / (area * std::fabs(cosL)));
  s.delta = 0u;
  return s;
}

// The density FromAreaPoint gives the point a ray from p found at dist along dir.
inline float AreaPointPdf(float3 normal, float area, float4 radiance, float3 dir, float dist)
{
  const float normalLength = LiteMath::length(normal);
  if (area <= 0.0f || normalLength <= 0.0f)
    return 0.0f;
  const float cosL = -LiteMath::dot(normal, dir) / normalLength;
  if (cosL == 0.0f || (cosL < 0.0f && radiance.w == 0.0f))
    return 0.0f;
  return dist * dist / (area * std::fabs(cosL));
}

// ---------------------------------------------------------------- an emissive triangle

struct TriangleLight : ILight
{
  float4 v0;        // xyz: the first corner
  float4 edge1;     // xyz: v1 - v0
  float4 edge2;     // xyz: v2 - v0
  float4 radiance;  // xyz: emitted radiance; w: 1 when it emits from both sides

  float3 Normal() const { return LiteMath::cross(to_float3(edge1), to_float3(edge2)); }  // length: twice the area

  LightSample Sample(float3 p, float2 u) const override
  {
    const float2 b = SampleTriangle(u.x, u.y);
    const float3 n = Normal();
    return FromAreaPoint(p, to_float3(v0) + to_float3(edge1) * b.x + to_float3(edge2) * b.y, n, 0.5f * LiteMath::length(n), radiance);
  }
  float Pdf(float3 p, float3 dir, float dist) const override
  {
    (void)p;
    const float3 n = Normal();
    return AreaPointPdf(n, 0.5f * LiteMath::length(n), radiance, dir, dist);
  }
  float Power() const override
  {
    return Luminance(to_float3(radiance)) * 0.5f * LiteMath::length(Normal()) * kPi * (radiance.w != 0.0f ? 2.0f : 1.0f);
  }
};

// ---------------------------------------------------------------- lights with shapes of their own

struct SphereLight : ILight
{
  float4 centerRadius;  // xyz: the centre; w: the radius
  float4 radiance;      // xyz

  // 1 - cos of the half-angle the sphere fills from p (0 when p is inside), written so that a small
  // distant sphere keeps its digits.
  float OneMinusCosMax(float3 p) const
  {
    const float3 d = to_float3(centerRadius) - p;
    const float dist2 = LiteMath::dot(d, d), r2 = centerRadius.w * centerRadius.w;
    if (dist2 <= r2)
      return 0.0f;
    const float sin2 = r2 / dist2;
    return sin2 / (1.0f + std::sqrt(1.0f - sin2));
  }
  LightSample Sample(float3 p, float2 u) const override
  {
    const float oneMinusCos = OneMinusCosMax(p);
    if (oneMinusCos <= 0.0f)
      return NoLight();
    const float3 d = to_float3(centerRadius) - p;
    const float3 w = LiteMath::normalize(d);
    float3 t, b;
    BranchlessOnb(w, t, b);
    const float cosT = 1.0f - u.x * oneMinusCos;
    const float sinT = std::sqrt(LiteMath::max(0.0f, 1.0f - cosT * cosT));
    const float phi = 2.0f * kPi * u.y;
    const float3 dir = t * (sinT * std::cos(phi)) + b * (sinT * std::sin(phi)) + w * cosT;
    const float dist = Intersect(p, dir);
    if (dist >= 1e30f)  // grazing the rim in float
      return NoLight();
    LightSample s;
    s.dirDist = to_float4(dir, dist);
    s.radiancePdf = to_float4(to_float3(radiance), 1.0f / (2.0f * kPi * oneMinusCos));
    s.delta = 0u;
    return s;
  }
  float Pdf(float3 p, float3 dir, float dist) const override
  {
    (void)dir, (void)dist;
    const float oneMinusCos = OneMinusCosMax(p);
    return oneMinusCos > 0.0f ? 1.0f / (2.0f * kPi * oneMinusCos) : 0.0f;
  }
  float Intersect(float3 p, float3 dir) const override
  {
    const float3 d = to_float3(centerRadius) - p;
    const float along = LiteMath::dot(d, dir);
    const float miss2 = LiteMath::dot(d, d) - along * along;  // squared distance of the line from the centre
    const float r2 = centerRadius.w * centerRadius.w;
    if (miss2 > r2)
      return 1e30f;
    const float half = std::sqrt(r2 - miss2);
    const float tNear = along - half, tFar = along + half;
    return tNear > 0.0f ? tNear : (tFar > 0.0f ? tFar : 1e30f);
  }
  float3 RadianceTowards(float3 dir) const override
  {
    (void)dir;
    return to_float3(radiance);
  }
  float Power() const override { return 4.0f * kPi * kPi * centerRadius.w * centerRadius.w * Luminance(to_float3(radiance)); }
};

struct RectLight : ILight
{
  float4 corner;    // xyz
  float4 edge1;     // xyz: along one side
  float4 edge2;     // xyz: along the other, at right angles; it emits towards cross(edge1, edge2)
  float4 radiance;  // xyz; w: 1 when it emits from both sides

  float3 Normal() const { return LiteMath::cross(to_float3(edge1), to_float3(edge2)); }  // length: the area

  LightSample Sample(float3 p, float2 u) const override
  {
    const float3 n = Normal();
    return FromAreaPoint(p, to_float3(corner) + to_float3(edge1) * u.x + to_float3(edge2) * u.y, n, LiteMath::length(n), radiance);
  }
  float Pdf(float3 p, float3 dir, float dist) const override
  {
    (void)p;
    const float3 n = Normal();
    return AreaPointPdf(n, LiteMath::length(n), radiance, dir, dist);
  }
  float Intersect(float3 p, float3 dir) const override
  {
    const float3 n = Normal();
    const float facing = LiteMath::dot(n, dir);
    if (facing == 0.0f)
      return 1e30f;
    const float t = LiteMath::dot(n, to_float3(corner) - p) / facing;
    if (t <= 0.0f)
      return 1e30f;
    const float3 q = p + dir * t - to_float3(corner);
    const float a = LiteMath::dot(q, to_float3(edge1)) / LiteMath::dot(to_float3(edge1), to_float3(edge1));
    const float b = LiteMath::dot(q, to_float3(edge2)) / LiteMath::dot(to_float3(edge2), to_float3(edge2));
    return a >= 0.0f && a <= 1.0f && b >= 0.0f && b <= 1.0f ? t : 1e30f;
  }
  float3 RadianceTowards(float3 dir) const override
  {
    return LiteMath::dot(Normal(), dir) < 0.0f || radiance.w != 0.0f ? to_float3(radiance) : float3(0.0f);
  }
  float Power() const override
  {
    return kPi * LiteMath::length(Normal()) * Luminance(to_float3(radiance)) * (radiance.w != 0.0f ? 2.0f : 1.0f);
  }
};

// ---------------------------------------------------------------- punctual lights

// Light of this intensity from the point q, as seen from p: intensity / d^2, a delta light.
inline LightSample FromPoint(float3 p, float3 q, float3 intensity)
{
  const float3 d = q - p;
  const float dist2 = LiteMath::dot(d, d);
  if (dist2 <= 0.0f)
    return NoLight();
  const float dist = std::sqrt(dist2);
  LightSample s;
  s.dirDist = to_float4(d * (1.0f / dist), dist);
  s.radiancePdf = to_float4(intensity * (1.0f / dist2), 1.0f);
  s.delta = 1u;
  return s;
}

struct PointLight : ILight
{
  float4 position;   // xyz
  float4 intensity;  // xyz: radiant intensity (radiance x area per steradian)

  LightSample Sample(float3 p, float2 u) const override
  {
    (void)u;
    return FromPoint(p, to_float3(position), to_float3(intensity));
  }
  float Power() const override { return 4.0f * kPi * Luminance(to_float3(intensity)); }
};

struct SpotLight : ILight
{
  float4 position;   // xyz
  float4 direction;  // xyz: unit, where the cone points
  float4 intensity;  // xyz: on the axis
  float cosInner = 0.9f;  // full intensity inside this cone
  float cosOuter = 0.8f;  // none outside this one

  LightSample Sample(float3 p, float2 u) const override
  {
    (void)u;
    LightSample s = FromPoint(p, to_float3(position), to_float3(intensity));
    const float cd = -LiteMath::dot(to_float3(s.dirDist), to_float3(direction));
    // glTF's recommended edge: a squared linear ramp in the cosine between the cones.
    const float t = LiteMath::clamp((cd - cosOuter) / LiteMath::max(cosInner - cosOuter, 1e-4f), 0.0f, 1.0f);
    s.radiancePdf = to_float4(to_float3(s.radiancePdf) * (t * t), s.radiancePdf.w * (t > 0.0f ? 1.0f : 0.0f));
    return s;
  }
  float Power() const override { return 2.0f * kPi * (1.0f - 0.5f * (cosInner + cosOuter)) * Luminance(to_float3(intensity)); }
};

struct DirectionalLight : ILight
{
  float4 direction;   // xyz: unit, where the light travels
  float4 irradiance;  // xyz: on a surface facing it
  float sceneRadius = 1.0f;  // for Power: the light falls on about pi r^2

  LightSample Sample(float3 p, float2 u) const override
  {
    (void)p, (void)u;
    LightSample s;
    s.dirDist = to_float4(-1.0f * to_float3(direction), 1e30f);
    s.radiancePdf = to_float4(to_float3(irradiance), 1.0f);
    s.delta = 1u;
    return s;
  }
  float Power() const override { return kPi * sceneRadius * sceneRadius * Luminance(to_float3(irradiance)); }
};

}  // namespace litept
