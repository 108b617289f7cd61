// The path tracer's light sources (libs/litept): a second virtual hierarchy. A light draws a point
// (or a direction) as seen from a shaded point, with the radiance arriving from it and the density
// of that choice in solid angle, and gives that density for a direction a BSDF drew, so that the two
// strategies combine by multiple importance sampling. The environment map is the integrator's own
// (it needs the map and its distribution, which live in the integrator's vectors).
//
//   TriangleLight     an emissive triangle, sampled uniformly by area (front side only unless
//                     two-sided); the scene's emissive meshes become one per triangle.
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
  // Roughly the power it emits (the weight for picking it among the scene's lights); host side.
  virtual float Power() const = 0;
};

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
    const float3 q = to_float3(v0) + to_float3(edge1) * b.x + to_float3(edge2) * b.y;
    const float3 d = q - p;
    const float dist2 = LiteMath::dot(d, d);
    const float3 n = Normal();
    const float area2 = LiteMath::length(n);
    if (dist2 <= 0.0f || area2 <= 0.0f)
      return NoLight();
    const float dist = std::sqrt(dist2);
    const float3 dir = d * (1.0f / dist);
    const float cosL = -LiteMath::dot(n, dir) / area2;
    if (cosL <= 0.0f && (radiance.w == 0.0f || cosL == 0.0f))
      return NoLight();
    LightSample s;
    s.dirDist = to_float4(dir, dist);
    s.radiancePdf = to_float4(to_float3(radiance), dist2 / (0.5f * area2 * std::fabs(cosL)));
    s.delta = 0u;
    return s;
  }
  float Pdf(float3 p, float3 dir, float dist) const override
  {
    (void)p;
    const float3 n = Normal();
    const float area2 = LiteMath::length(n);
    const float cosL = -LiteMath::dot(n, dir) / area2;
    if (area2 <= 0.0f || cosL == 0.0f || (cosL < 0.0f && radiance.w == 0.0f))
      return 0.0f;
    return dist * dist / (0.5f * area2 * std::fabs(cosL));
  }
  float Power() const override
  {
    return Luminance(to_float3(radiance)) * 0.5f * LiteMath::length(Normal()) * kPi * (radiance.w != 0.0f ? 2.0f : 1.0f);
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
