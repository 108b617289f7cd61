// The path tracer's numbers and warps (libs/litept): scrambled Sobol and hashed numbers that depend
// only on (pixel, sample, bounce, dimension), so every backend and thread count draws the same path;
// the maps from the unit square to directions, with their densities; Fresnel terms; and GGX, the
// microfacet distribution every rough material here uses. Plain inline functions over LiteMath: the translator
// prints the ones kernels reach for the GPU.
#pragma once
#include "LiteMath.h"

#include <cmath>
#include <cstdint>

namespace litept {

using LiteMath::float2;
using LiteMath::float3;
using LiteMath::float4;
using LiteMath::uint4;

constexpr float kPi = 3.14159265358979f;
constexpr float kInvPi = 0.318309886183791f;

// ---------------------------------------------------------------- random numbers
//
// The numbers of a path vertex come four at a time. At the camera and the first surface hit they
// are a 4D Sobol sequence, Owen-scrambled and shuffled by hashing (Burley 2020, "Practical
// Hash-based Owen Scrambling"): a pixel's first 2^m samples of each group of four stay a stratified
// (0, m, 2)-net in the first two numbers, and each pixel and group gets its own scramble and order,
// so neither pixels nor groups correlate. Deeper vertices take hashed numbers: there stratification
// gains little and the scrambling's cost shows. Measured on the Cornell box at 512 spp, against
// hashed numbers throughout: Sobol at the camera and the first hit, 13% less error for 16% more
// time (it pays in direct light and at low spp); at every vertex, 15% less error for 50% more time.

// A well-mixed 32-bit hash (the PCG output permutation).
inline uint32_t PcgHash(uint32_t x)
{
  const uint32_t state = x * 747796405u + 2891336453u;
  const uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

inline uint32_t ReverseBits(uint32_t x)
{
  x = ((x >> 1u) & 0x55555555u) | ((x & 0x55555555u) << 1u);
  x = ((x >> 2u) & 0x33333333u) | ((x & 0x33333333u) << 2u);
  x = ((x >> 4u) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4u);
  x = ((x >> 8u) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8u);
  return (x >> 16u) | (x << 16u);
}

// A random permutation of [0, 2^32) that is a nested uniform (Owen) scramble of the bits read from
// the top: each bit flips with a hash of the bits above it. Burley's variant of the Laine-Karras
// hash, which mixes upwards only, applied to the reversed bits.
inline uint32_t OwenScramble(uint32_t x, uint32_t seed)
{
  x = ReverseBits(x);
  x += seed;
  x ^= x * 0x6C50B47Cu;
  x ^= x * 0xB82F1E52u;
  x ^= x * 0xC7AFE638u;
  x ^= x * 0x8D22F6E6u;
  return ReverseBits(x);
}

// The index-th point of the first four Sobol dimensions as 32-bit fractions. The direction numbers
// follow from their primitive polynomials (Joe and Kuo's first four), so no table is needed:
// dimension 0 is the van der Corput sequence, 1 has degree 1, 2 degree 2 (m = 1, 3) and 3 degree 3
// (m = 1, 3, 1), each step v_k = sum of a_j v_{k-j} ^ v_{k-s} ^ (v_{k-s} >> s).
inline uint4 Sobol4(uint32_t index)
{
  uint4 x(0u, 0u, 0u, 0u);
  uint32_t v0 = 0x80000000u, v1 = 0x80000000u;
  uint32_t v2 = 0x80000000u, v2Prev = 0u;                 // v_k, v_{k-1}
  uint32_t v3 = 0x80000000u, v3Prev = 0u, v3Prev2 = 0u;  // v_k, v_{k-1}, v_{k-2}
  for (uint32_t k = 0u; index != 0u; ++k, index >>= 1u)
  {
    if ((index & 1u) != 0u)
    {
      x.x ^= v0;
      x.y ^= v1;
      x.z ^= v2;
      x.w ^= v3;
    }
    v0 >>= 1u;
    v1 ^= v1 >> 1u;
    const uint32_t v2Next = k == 0u ? 0xC0000000u : v2 ^ v2Prev ^ (v2Prev >> 2u);
    v2Prev = v2;
    v2 = v2Next;
    const uint32_t v3Next = k == 0u ? 0xC0000000u : (k == 1u ? 0x20000000u : v3Prev ^ v3Prev2 ^ (v3Prev2 >> 3u));
    v3Prev2 = v3Prev;
    v3Prev = v3;
    v3 = v3Next;
  }
  return x;
}

// A 32-bit fraction as a float in [0, 1): its top 24 bits, exact, so every backend agrees.
inline float UnitFloat(uint32_t bits) { return float(bits >> 8u) * (1.0f / 16777216.0f); }

// Sobol points are drawn for vertices below this (0 is the camera, 1 the first surface hit).
constexpr uint32_t kSobolVertices = 2u;

// A uniform number from hashing (pixel, sample, bounce, dimension).
inline float HashedFloat(uint32_t pixel, uint32_t sample, uint32_t bounce, uint32_t dimension)
{
  return UnitFloat(PcgHash(pixel ^ PcgHash(sample * 0x9E3779B9u ^ PcgHash(bounce * 0x85EBCA6Bu + dimension))));
}

// The four numbers of one vertex of a path: group `slot` of vertex `bounce`, sample `sample` of
// `pixel`. Depends on nothing else, so every backend and thread count draws the same path.
inline float4 Random4(uint32_t pixel, uint32_t sample, uint32_t bounce, uint32_t slot)
{
  if (bounce >= kSobolVertices)
    return float4(HashedFloat(pixel, sample, bounce, 4u * slot), HashedFloat(pixel, sample, bounce, 4u * slot + 1u),
                  HashedFloat(pixel, sample, bounce, 4u * slot + 2u), HashedFloat(pixel, sample, bounce, 4u * slot + 3u));
  const uint32_t seed = PcgHash(pixel ^ PcgHash(bounce * 0x85EBCA6Bu + slot * 0x9E3779B9u));
  // The shuffled index keeps a prefix of 2^m samples within one block of the sequence; dropping the
  // block's constant top bits (an XOR, so still a permutation) keeps the Sobol loop to 16 steps.
  const uint32_t index = OwenScramble(sample, seed) ^ (OwenScramble(0u, seed) & 0xFFFF0000u);
  const uint4 p = Sobol4(index);
  return float4(UnitFloat(OwenScramble(p.x, PcgHash(seed + 1u))), UnitFloat(OwenScramble(p.y, PcgHash(seed + 2u))),
                UnitFloat(OwenScramble(p.z, PcgHash(seed + 3u))), UnitFloat(OwenScramble(p.w, PcgHash(seed + 4u))));
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
