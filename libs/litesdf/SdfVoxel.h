// Ray against one voxel of a signed distance field: the trilinear interpolant of its 8 corner
// values along the ray is a cubic in t (Söderlund, Evans and Akenine-Möller, "Ray Tracing of Signed
// Distance Function Grids", JCGT 2022). Its first root is found by splitting the interval at the
// roots of the derivative and running Newton's method with a bisection safeguard in the first
// piece whose ends differ in sign. Plain functions on LiteMath types, so that kernels can call them.
#pragma once
#include "LiteMath.h"

#include <cmath>
#include <cstdint>

namespace litesdf {

using LiteMath::float3;

// Corner values of a voxel, corner (x, y, z) at index x + 2y + 4z.
struct VoxelValues {
  float v[8];
};

// The trilinear interpolant written as A + Bx + Cy + Dz + Exy + Fxz + Gyz + Hxyz over [0,1]^3.
struct TrilinearTerms {
  float A, B, C, D, E, F, G, H;
};

inline TrilinearTerms TrilinearOf(const VoxelValues& s) {
  TrilinearTerms k;
  k.A = s.v[0];
  k.B = s.v[1] - s.v[0];
  k.C = s.v[2] - s.v[0];
  k.D = s.v[4] - s.v[0];
  k.E = s.v[3] - s.v[1] - s.v[2] + s.v[0];
  k.F = s.v[5] - s.v[1] - s.v[4] + s.v[0];
  k.G = s.v[6] - s.v[2] - s.v[4] + s.v[0];
  k.H = s.v[7] - s.v[3] - s.v[5] - s.v[6] + s.v[1] + s.v[2] + s.v[4] - s.v[0];
  return k;
}

inline float EvalTrilinear(const TrilinearTerms& k, float3 u) {
  return k.A + k.B * u.x + k.C * u.y + k.D * u.z + k.E * u.x * u.y + k.F * u.x * u.z + k.G * u.y * u.z + k.H * u.x * u.y * u.z;
}

// The gradient of the interpolant in voxel units (multiply by 1 / voxel size for world units).
inline float3 GradTrilinear(const TrilinearTerms& k, float3 u) {
  return float3(k.B + k.E * u.y + k.F * u.z + k.H * u.y * u.z,
                k.C + k.E * u.x + k.G * u.z + k.H * u.x * u.z,
                k.D + k.F * u.x + k.G * u.y + k.H * u.x * u.y);
}

// f(a + t b) = c0 + c1 t + c2 t^2 + c3 t^3, for a point a and a direction b in voxel units.
struct Cubic {
  float c0, c1, c2, c3;
};

inline Cubic CubicAlongRay(const TrilinearTerms& k, float3 a, float3 b) {
  Cubic c;
  c.c0 = EvalTrilinear(k, a);
  c.c1 = k.B * b.x + k.C * b.y + k.D * b.z + k.E * (a.x * b.y + a.y * b.x) + k.F * (a.x * b.z + a.z * b.x) +
         k.G * (a.y * b.z + a.z * b.y) + k.H * (a.x * a.y * b.z + a.x * a.z * b.y + a.y * a.z * b.x);
  c.c2 = k.E * b.x * b.y + k.F * b.x * b.z + k.G * b.y * b.z + k.H * (a.x * b.y * b.z + a.y * b.x * b.z + a.z * b.x * b.y);
  c.c3 = k.H * b.x * b.y * b.z;
  return c;
}

inline float EvalCubic(const Cubic& c, float t) { return c.c0 + t * (c.c1 + t * (c.c2 + t * c.c3)); }
inline float EvalCubicDerivative(const Cubic& c, float t) { return c.c1 + t * (2.0f * c.c2 + t * 3.0f * c.c3); }

// A root of the cubic in [t0, t1], where f(t0) and f(t1) differ in sign (or one is 0) and f is
// monotone: Newton's method from the end nearer the root, kept inside the bracket by bisection.
inline float SolveBracketed(const Cubic& c, float t0, float t1, float f0, float f1, int iterations) {
  float lo = t0, hi = t1, flo = f0;
  float t = (std::fabs(f0) < std::fabs(f1)) ? t0 : t1;
  for (int i = 0; i < iterations; ++i) {
    const float f = EvalCubic(c, t);
    if (f == 0.0f) return t;
    if ((f < 0.0f) == (flo < 0.0f)) { lo = t; flo = f; }
    else hi = t;
    const float d = EvalCubicDerivative(c, t);
    float next = d != 0.0f ? t - f / d : 0.5f * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5f * (lo + hi);  // Newton left the bracket (or NaN): bisect
    t = next;
  }
  return t;
}

// The first t in [t0, t1] where the cubic, positive at t0, reaches 0; -1 when it does not.
inline float FirstRoot(const Cubic& c, float t0, float t1, int iterations) {
  // Split at the derivative's roots: 3 c3 t^2 + 2 c2 t + c1 = 0. Between splits f is monotone.
  float splits[4];
  int n = 0;
  splits[n++] = t0;
  const float qa = 3.0f * c.c3, qb = 2.0f * c.c2, qc = c.c1;
  if (std::fabs(qa) > 1e-12f) {
    const float disc = qb * qb - 4.0f * qa * qc;
    if (disc >= 0.0f) {
      const float s = std::sqrt(disc);
      // The numerically stable pair of roots.
      const float q = -0.5f * (qb + (qb >= 0.0f ? s : -s));
      float r0 = q / qa, r1 = q != 0.0f ? qc / q : r0;
      if (r0 > r1) { const float tmp = r0; r0 = r1; r1 = tmp; }
      if (r0 > t0 && r0 < t1) splits[n++] = r0;
      if (r1 > t0 && r1 < t1 && r1 != r0) splits[n++] = r1;
    }
  } else if (std::fabs(qb) > 1e-12f) {
    const float r = -qc / qb;
    if (r > t0 && r < t1) splits[n++] = r;
  }
  splits[n++] = t1;
  float fa = EvalCubic(c, splits[0]);
  if (!(fa > 0.0f)) return fa <= 0.0f ? splits[0] : -1.0f;  // already inside; NaN misses
  for (int i = 0; i + 1 < n; ++i) {
    const float fb = EvalCubic(c, splits[i + 1]);
    if (fb <= 0.0f) return SolveBracketed(c, splits[i], splits[i + 1], fa, fb, iterations);
    fa = fb;
  }
  return -1.0f;
}

// Where a ray meets an axis-aligned box: [tNear, tFar], empty when tNear > tFar. NaN-safe: a NaN
// ray misses.
inline bool RayBox(float3 origin, float3 invDir, float3 boxMin, float3 boxMax, float tmin, float tmax, float& tNear, float& tFar) {
  if (!(tmin <= tmax)) return false;  // also a NaN tmin or tmax
  const float3 lo = (boxMin - origin) * invDir, hi = (boxMax - origin) * invDir;
  const float3 n = LiteMath::min(lo, hi), f = LiteMath::max(lo, hi);
  tNear = std::fmax(std::fmax(n.x, n.y), std::fmax(n.z, tmin));
  tFar = std::fmin(std::fmin(f.x, f.y), std::fmin(f.z, tmax));
  return tNear <= tFar;  // false for NaN
}

struct SdfHit {
  float t;         // along the ray; -1 when it missed
  float3 normal;   // the interpolant's normalised gradient, world space
};

inline SdfHit Missed() {
  SdfHit hit;
  hit.t = -1.0f;
  hit.normal = float3(0.0f, 0.0f, 0.0f);
  return hit;
}

// The ray's span [tNear, tFar] inside the voxel [voxelMin, voxelMin + size]^3, with corner values
// `values`: its first point on the surface. The entry point is clamped onto the voxel (snapped to its
// faces), so that neighbouring voxels, which share the values of their common face, agree where a
// ray crosses from one to the other. A ray that enters the voxel inside the surface (value <= 0: it
// starts inside, or came from cells wholly inside, which a sparse set does not store) hits where it
// enters: a ray that starts inside hits before it could leave the shape.
[[gnu::always_inline]] inline SdfHit IntersectVoxelSpan(const VoxelValues& values, float3 voxelMin, float size, float3 origin, float3 dir,
                                                        float tNear, float tFar, int newtonIterations) {
  SdfHit hit = Missed();
  if (!(tNear <= tFar)) return hit;
  const float invSize = 1.0f / size;
  const float3 a = LiteMath::clamp((origin + tNear * dir - voxelMin) * invSize, float3(0.0f, 0.0f, 0.0f), float3(1.0f, 1.0f, 1.0f));
  const float3 b = dir * invSize;
  const TrilinearTerms k = TrilinearOf(values);
  const Cubic c = CubicAlongRay(k, a, b);
  const float t = FirstRoot(c, 0.0f, tFar - tNear, newtonIterations);
  if (t < 0.0f) return hit;
  hit.t = tNear + t;
  const float3 u = LiteMath::clamp(a + t * b, float3(0.0f, 0.0f, 0.0f), float3(1.0f, 1.0f, 1.0f));
  const float3 g = GradTrilinear(k, u);
  const float len = LiteMath::length(g);
  hit.normal = len > 0.0f ? g / len : float3(0.0f, 0.0f, 0.0f);
  return hit;
}

// Ray (origin, dir, [tmin, tmax]) against the voxel [voxelMin, voxelMin + size]^3.
inline SdfHit IntersectVoxel(const VoxelValues& values, float3 voxelMin, float size, float3 origin, float3 dir, float tmin, float tmax,
                             int newtonIterations) {
  const float3 invDir = float3(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z);
  float tNear = 0.0f, tFar = 0.0f;
  if (!RayBox(origin, invDir, voxelMin, voxelMin + float3(size, size, size), tmin, tmax, tNear, tFar)) return Missed();
  return IntersectVoxelSpan(values, voxelMin, size, origin, dir, tNear, tFar, newtonIterations);
}

// Whether some point of the voxel may lie on or inside the surface: the interpolant's minimum is at
// a corner.
inline bool MayHoldSurface(const VoxelValues& values) {
  float lowest = values.v[0];
  for (int c = 1; c < 8; ++c) lowest = values.v[c] < lowest ? values.v[c] : lowest;
  return lowest <= 0.0f;
}

// The voxels of a box of n[0] x n[1] x n[2] voxels of edge `size` from boxMin that the ray crosses
// within [t0, t1] (its span inside the box), in order along the ray (Amanatides and Woo): calls
// `voxel(x, y, z, voxelMin, tEnter, tLeave)` for each until one returns a hit, and returns it.
template <class Voxel>
SdfHit MarchVoxels(const int n[3], float3 boxMin, float size, float3 origin, float3 dir, float t0, float t1, Voxel voxel) {
  const float3 entry = (origin + t0 * dir - boxMin) / size;
  int cell[3], step[3];
  float tNext[3], tDelta[3];
  for (int a = 0; a < 3; ++a) {
    cell[a] = LiteMath::clamp(int(std::floor(entry[a])), 0, n[a] - 1);
    step[a] = dir[a] > 0.0f ? 1 : -1;
    const float boundary = boxMin[a] + size * float(cell[a] + (dir[a] > 0.0f ? 1 : 0));
    tNext[a] = dir[a] != 0.0f ? (boundary - origin[a]) / dir[a] : INFINITY;
    tDelta[a] = dir[a] != 0.0f ? size / std::fabs(dir[a]) : INFINITY;
  }
  float tEnter = t0;
  while (true) {
    const int a = tNext[0] < tNext[1] ? (tNext[0] < tNext[2] ? 0 : 2) : (tNext[1] < tNext[2] ? 1 : 2);
    const float tLeave = tNext[a] < t1 ? tNext[a] : t1;
    const float3 voxelMin = boxMin + size * float3(float(cell[0]), float(cell[1]), float(cell[2]));
    const SdfHit h = voxel(cell[0], cell[1], cell[2], voxelMin, tEnter, tLeave);
    if (h.t >= 0.0f) return h;
    if (!(tNext[a] <= t1)) return Missed();  // left the box (or the ray's end)
    cell[a] += step[a];
    if (cell[a] < 0 || cell[a] >= n[a]) return Missed();
    tEnter = tNext[a];
    tNext[a] += tDelta[a];
  }
}

}  // namespace litesdf
