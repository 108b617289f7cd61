// The path tracer's numbers and warps (libs/litept): random numbers that depend only on (pixel,
// sample, bounce, dimension), so every backend and thread count draws the same path; the maps from
// the unit square to directions, with their densities; Fresnel terms; and GGX, the microfacet
// distribution every rough material here uses. Plain inline functions over LiteMath: the translator
// prints the ones kernels reach for the GPU.
#pragma once
#include "LiteMath.h"

#include <cmath>
#include <cstdint>

namespace litept {

using LiteMath::float2;
using LiteMath::float3;
using LiteMath::float4;

constexpr float kPi = 3.14159265358979f;
constexpr float kInvPi = 0.318309886183791f;

// ---------------------------------------------------------------- random numbers

// A well-mixed 32-bit hash (the PCG output permutation).
inline uint32_t PcgHash(uint32_t x)
{
  const uint32_t state = x * 747796405u + 2891336453u;
  const uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// Uniform in [0, 1): 24 random bits, exact in float, so every backend gets the same number.
inline float RandomFloat(uint32_t pixel, uint32_t sample, uint32_t bounce, uint32_t dimension)
{
  const uint32_t h = PcgHash(pixel ^ PcgHash(sample * 0x9E3779B9u ^ PcgHash(bounce * 0x85EBCA6Bu + dimension)));
  return float(h >> 8u) * (1.0f / 16777216.0f);
}

// Four uniform numbers of one vertex of a path: dimensions 4 * slot .. 4 * slot + 3.
inline float4 Random4(uint32_t pixel, uint32_t sample, uint32_t bounce, uint32_t slot)
{
  return float4(RandomFloat(pixel, sample, bounce, 4u * slot), RandomFloat(pixel, sample, bounce, 4u * slot + 1u),
                RandomFloat(pixel, sample, bounce, 4u * slot + 2u), RandomFloat(pixel, sample, bounce, 4u * slot + 3u));
}

// ---------------------------------------------------------------- frames

// An orthonormal basis (tangent, bitangent) around a unit normal (Duff et al. 2017, no branch on
// a threshold, so no seam).
inline void BranchlessOnb(float3 n, float3& t, float3& b)
{
  const float sign = n.z >= 0.0f ? 1.0f : -1.0f;
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = float3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = float3(c, sign + n.y * n.y * a, -n.y);
}

inline float3 ToLocal(float3 v, float3 t, float3 b, float3 n) { return float3(LiteMath::dot(v, t), LiteMath::dot(v, b), LiteMath::dot(v, n)); }
inline float3 ToWorld(float3 v, float3 t, float3 b, float3 n) { return t * v.x + b * v.y + n * v.z; }

// ---------------------------------------------------------------- warps

// Cosine-weighted direction about +z; its density is z / pi.
inline float3 SampleCosineHemisphere(float u1, float u2)
{
  const float r = std::sqrt(u1);
  const float phi = 2.0f * kPi * u2;
  return float3(r * std::cos(phi), r * std::sin(phi), std::sqrt(LiteMath::max(0.0f, 1.0f - u1)));
}

// Uniform point on a triangle as barycentrics (b1, b2) of its second and third corners (the
// square-root map, Shirley and Chiu).
inline float2 SampleTriangle(float u1, float u2)
{
  const float s = std::sqrt(u1);
  return float2(s * (1.0f - u2), s * u2);
}

// The power heuristic with beta 2 (Veach), for one sample of each strategy.
inline float PowerHeuristic(float pdfA, float pdfB)
{
  const float a = pdfA * pdfA, b = pdfB * pdfB;
  return a + b > 0.0f ? a / (a + b) : 0.0f;
}

inline float Luminance(float3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// ---------------------------------------------------------------- Fresnel

inline float SchlickWeight(float cosTheta)
{
  const float m = LiteMath::clamp(1.0f - cosTheta, 0.0f, 1.0f);
  const float m2 = m * m;
  return m2 * m2 * m;
}

inline float3 FresnelSchlick(float3 f0, float cosTheta) { return f0 + (float3(1.0f) - f0) * SchlickWeight(cosTheta); }

// Unpolarised Fresnel reflectance of a dielectric interface; cosThetaI > 0 on the side the
// normal points to, eta = the inside's index over the outside's. 1 under total internal reflection.
inline float FresnelDielectric(float cosThetaI, float eta)
{
  float cosI = LiteMath::clamp(cosThetaI, -1.0f, 1.0f);
  float e = eta;
  if (cosI < 0.0f)  // leaving: swap the sides
  {
    e = 1.0f / eta;
    cosI = -cosI;
  }
  const float sin2T = (1.0f - cosI * cosI) / (e * e);
  if (sin2T >= 1.0f)
    return 1.0f;
  const float cosT = std::sqrt(LiteMath::max(0.0f, 1.0f - sin2T));
  const float rParl = (e * cosI - cosT) / (e * cosI + cosT);
  const float rPerp = (cosI - e * cosT) / (cosI + e * cosT);
  return 0.5f * (rParl * rParl + rPerp * rPerp);
}

// Fresnel reflectance of a conductor with complex index eta + i k (per channel), for light
// arriving at cosThetaI >= 0 from a medium of index 1.
inline float FresnelConductor1(float cosThetaI, float eta, float k)
{
  const float c2 = cosThetaI * cosThetaI;
  const float s2 = 1.0f - c2;
  const float eta2 = eta * eta, k2 = k * k;
  const float t0 = eta2 - k2 - s2;
  const float a2b2 = std::sqrt(LiteMath::max(0.0f, t0 * t0 + 4.0f * eta2 * k2));
  const float a = std::sqrt(LiteMath::max(0.0f, 0.5f * (a2b2 + t0)));
  const float t1 = a2b2 + c2;
  const float t2 = 2.0f * a * cosThetaI;
  const float rs = (t1 - t2) / LiteMath::max(t1 + t2, 1e-12f);
  const float t3 = c2 * a2b2 + s2 * s2;
  const float t4 = t2 * s2;
  const float rp = rs * (t3 - t4) / LiteMath::max(t3 + t4, 1e-12f);
  return 0.5f * (rp + rs);
}

inline float3 FresnelConductor(float cosThetaI, float3 eta, float3 k)
{
  return float3(FresnelConductor1(cosThetaI, eta.x, k.x), FresnelConductor1(cosThetaI, eta.y, k.y), FresnelConductor1(cosThetaI, eta.z, k.z));
}

// ---------------------------------------------------------------- GGX (Trowbridge-Reitz)
// alpha is the glTF / Cycles roughness squared. Directions are local: +z is the normal.

inline float GgxD(float3 h, float alpha)
{
  // cos^2 alpha^2 + sin^2 for a unit h: written as 1 + cos^2 (alpha^2 - 1) it rounds to 0 at
  // alpha^2 below float's epsilon (glTF roughness 0) and h along the normal.
  const float a2 = alpha * alpha;
  const float d = h.z * h.z * a2 + h.x * h.x + h.y * h.y;
  return a2 / (kPi * d * d);
}

// Smith's Lambda for GGX.
inline float GgxLambda(float3 w, float alpha)
{
  const float c2 = w.z * w.z;
  if (c2 <= 0.0f)
    return 0.0f;
  const float tan2 = LiteMath::max(0.0f, 1.0f - c2) / c2;
  return 0.5f * (-1.0f + std::sqrt(1.0f + alpha * alpha * tan2));
}

inline float GgxG1(float3 w, float alpha) { return 1.0f / (1.0f + GgxLambda(w, alpha)); }

// The height-correlated masking-shadowing term.
inline float GgxG2(float3 wo, float3 wi, float alpha) { return 1.0f / (1.0f + GgxLambda(wo, alpha) + GgxLambda(wi, alpha)); }

// A microfacet normal drawn from the distribution of normals visible from wo (wo.z > 0): Heitz
// 2018, "Sampling the GGX distribution of visible normals". Its density is
// G1(wo) max(0, wo.h) D(h) / wo.z.
inline float3 SampleGgxVisibleNormal(float3 wo, float alpha, float u1, float u2)
{
  const float3 vh = LiteMath::normalize(float3(alpha * wo.x, alpha * wo.y, wo.z));
  const float lensq = vh.x * vh.x + vh.y * vh.y;
  const float3 t1 = lensq > 0.0f ? float3(-vh.y, vh.x, 0.0f) * (1.0f / std::sqrt(lensq)) : float3(1.0f, 0.0f, 0.0f);
  const float3 t2 = LiteMath::cross(vh, t1);
  const float r = std::sqrt(u1);
  const float phi = 2.0f * kPi * u2;
  const float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  const float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * std::sqrt(LiteMath::max(0.0f, 1.0f - p1 * p1)) + s * p2;
  const float3 nh = t1 * p1 + t2 * p2 + vh * std::sqrt(LiteMath::max(0.0f, 1.0f - p1 * p1 - p2 * p2));
  return LiteMath::normalize(float3(alpha * nh.x, alpha * nh.y, LiteMath::max(1e-6f, nh.z)));
}

// Density of reflecting wo into wi about h = normalize(wo + wi) with the visible-normal sampler.
inline float GgxReflectionPdf(float3 wo, float3 h, float alpha)
{
  return GgxG1(wo, alpha) * GgxD(h, alpha) / (4.0f * LiteMath::max(wo.z, 1e-8f));
}

}  // namespace litept
