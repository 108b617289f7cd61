// litesdf: the cubic along a ray, quantisation, the builders' sign test, and rays against the
// sparse voxel and brick sets at the extremes (faces, edges, corners, inside starts, tmin/tmax
// inside a voxel, NaN and inf, scales 1e-3 to 1e3), against exact analytic answers.
#include "SdfBVH.h"
#include "SdfTrace.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

using namespace litesdf;
using LiteMath::float3;

namespace {

// The exact first hit of a ray with the sphere (center 0), or -1.
float ExactSphereHit(float3 o, float3 d, float radius) {
  const float b = LiteMath::dot(o, d), c = LiteMath::dot(o, o) - radius * radius;
  const float disc = b * b - c;
  if (disc < 0.0f) return -1.0f;
  const float t = -b - std::sqrt(disc);
  return t >= 0.0f ? t : -1.0f;
}

float3 RandomUnit(std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  float3 v(n(rng), n(rng), n(rng));
  return LiteMath::normalize(v);
}

struct RayStats {
  int rays = 0, misses = 0;
  float maxError = 0.0f, minNormalDot = 1.0f;
};

// Rays from a sphere of radius 3 at points within `aim` of the centre; each must hit the sphere of
// `radius` where the exact answer says.
template <class Trace>
RayStats SphereRays(Trace trace, float radius, float scale, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  RayStats s;
  for (int i = 0; i < count; ++i) {
    const float3 origin = 3.0f * scale * RandomUnit(rng);
    const float3 target = 0.5f * radius * float3(u(rng), u(rng), u(rng));
    const float3 dir = LiteMath::normalize(target - origin);
    const float exact = ExactSphereHit(origin, dir, radius);
    REQUIRE(exact > 0.0f);
    const SdfHit hit = trace(origin, dir);
    ++s.rays;
    if (hit.t < 0.0f) {
      ++s.misses;
      continue;
    }
    s.maxError = std::max(s.maxError, std::fabs(hit.t - exact) / scale);
    const float3 n = LiteMath::normalize(origin + exact * dir);
    s.minNormalDot = std::min(s.minNormalDot, LiteMath::dot(n, hit.normal));
  }
  return s;
}

}  // namespace

TEST_CASE("SDF: the cubic along a ray is the trilinear interpolant", "[sdf]")
{
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), p(0.0f, 1.0f);
  for (int i = 0; i < 200; ++i) {
    VoxelValues v;
    for (float& x : v.v) x = u(rng);
    const TrilinearTerms k = TrilinearOf(v);
    for (uint32_t c = 0; c < 8; ++c)  // the terms reproduce the corners
      REQUIRE(EvalTrilinear(k, float3(float(c & 1), float((c >> 1) & 1), float(c >> 2))) == Approx(v.v[c]).margin(1e-6));
    const float3 a(p(rng), p(rng), p(rng)), b(u(rng), u(rng), u(rng));
    const Cubic cubic = CubicAlongRay(k, a, b);
    for (float t = 0.0f; t <= 1.0f; t += 0.125f)
      REQUIRE(EvalCubic(cubic, t) == Approx(EvalTrilinear(k, a + t * b)).margin(1e-5));
  }
}

TEST_CASE("SDF: quantised distances round-trip within half a step of the voxel diagonal", "[sdf]")
{
  std::mt19937 rng(2);
  const float diagonal = 0.1f;
  std::uniform_real_distribution<float> d(-diagonal, diagonal);
  for (uint32_t bytes : {1u, 2u, 4u}) {
    // Half a step, plus float rounding of the values themselves.
    const float bound = bytes == 4 ? 0.0f : diagonal / float((1u << (8 * bytes)) - 1u) + 4.0f * diagonal * 1.2e-7f;
    float worst = 0.0f;
    for (int i = 0; i < 10000; ++i) {
      const float x = d(rng);
      worst = std::max(worst, std::fabs(DequantiseDistance(QuantiseDistance(x, diagonal, bytes), diagonal, bytes) - x));
    }
    INFO(bytes << " bytes per value: worst " << worst << ", bound " << bound);
    CHECK(worst <= bound);
    // Beyond the diagonal a value saturates with its sign kept.
    if (bytes < 4) {
      CHECK(DequantiseDistance(QuantiseDistance(5.0f, diagonal, bytes), diagonal, bytes) == Approx(diagonal));
      CHECK(DequantiseDistance(QuantiseDistance(-5.0f, diagonal, bytes), diagonal, bytes) == Approx(-diagonal));
    }
  }
  // Packing: neighbours in a word do not disturb each other.
  std::vector<uint32_t> words(4, 0u);
  for (uint32_t i = 0; i < 8; ++i) PackValue(words, i, 0xA0u + i, 1);
  PackValue(words, 3, 0x11u, 1);
  for (uint32_t i = 0; i < 8; ++i) CHECK(UnpackValue(words, i, 1) == (i == 3 ? 0x11u : 0xA0u + i));
}

TEST_CASE("SDF: the builders keep only voxels whose interpolant changes sign, and say what they take", "[sdf]")
{
  const SdfSphere sphere(float3(0.0f, 0.0f, 0.0f), 0.7f);
  SdfBuildStats svsStats, sbsStats;
  const SdfSVS svs = BuildSVS(sphere, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, 2, &svsStats);
  const SdfSBS sbs = BuildSBS(sphere, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, 4, 1, &sbsStats);
  INFO("SVS: visited " << svsStats.cellsVisited << ", crossable " << svsStats.voxelsCrossable << ", kept " << svsStats.voxelsKept);
  REQUIRE(svs.VoxelCount() == svsStats.voxelsKept);
  CHECK(svsStats.voxelsKept > 0);
  CHECK(svsStats.voxelsKept < svsStats.voxelsCrossable);       // the sign test saves voxels
  CHECK(svsStats.cellsVisited < 32u * 32u * 32u / 4u);          // the octree skips most of the box
  CHECK(svs.Bytes() == svs.VoxelCount() * (4 + 8 * 2));          // coordinates + 8 two-byte values
  CHECK(sbs.Bytes() == sbs.BrickCount() * (4 + 4 * ((125 + 3) / 4)));  // 5^3 one-byte values per 4^3 brick
  // Every voxel of the dense grid that the sphere crosses is in the SVS.
  const SdfGrid grid = BuildGrid(sphere, float3(-1.0f, -1.0f, -1.0f), 2.0f, 33);
  uint64_t crossing = 0;
  for (uint32_t z = 0; z < 32; ++z)
    for (uint32_t y = 0; y < 32; ++y)
      for (uint32_t x = 0; x < 32; ++x) {
        float lo = 1e9f, hi = -1e9f;
        for (uint32_t c = 0; c < 8; ++c) {
          const float v = grid.Value(x + (c & 1), y + ((c >> 1) & 1), z + (c >> 2));
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
        crossing += lo <= 0.0f && hi >= 0.0f;
      }
  CHECK(crossing == svs.VoxelCount());
  CHECK_THROWS_WITH(BuildSVS(sphere, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, 3), "bytes per value must be 1, 2 or 4, not 3");
  CHECK_THROWS_WITH(BuildSBS(sphere, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, 3, 1), "brick size must be a power of 2 no larger than 2^depth, not 3");
}

namespace {
// A sphere whose distance throws past a plane: an ISdf that fails partway through a build.
class FailingSphere : public SdfSphere {
public:
  FailingSphere() : SdfSphere(float3(0.0f, 0.0f, 0.0f), 0.7f) {}
  float Distance(float3 p) const override {
    if (p.x > 0.5f) throw std::runtime_error("no distance past x = 0.5");
    return SdfSphere::Distance(p);
  }
};
}  // namespace

TEST_CASE("SDF: the builders run on all cores, with one result, and pass on an ISdf's exception", "[sdf]")
{
  // Built twice: the values are computed in parallel and packed in order, so the two are equal bit
  // for bit, in the octree's (Morton) order.
  const SdfTorus torus(float3(0.05f, -0.02f, 0.01f), 0.6f, 0.2f);
  const SdfSBS a = BuildSBS(torus, float3(-1.0f, -1.0f, -1.0f), 2.0f, 6, 4, 2), b = BuildSBS(torus, float3(-1.0f, -1.0f, -1.0f), 2.0f, 6, 4, 2);
  REQUIRE(a.BrickCount() > 100);
  CHECK(a.coords == b.coords);
  CHECK(a.values == b.values);
  const SdfSVS c = BuildSVS(torus, float3(-1.0f, -1.0f, -1.0f), 2.0f, 6, 1), d = BuildSVS(torus, float3(-1.0f, -1.0f, -1.0f), 2.0f, 6, 1);
  CHECK(c.coords == d.coords);
  CHECK(c.values == d.values);
  CHECK(std::is_sorted(c.coords.begin(), c.coords.end(), [](uint32_t l, uint32_t r) {
    auto morton = [](uint32_t v) {  // interleaves x, y, z (10 bits each) as the octree visits them
      uint64_t m = 0;
      for (uint32_t bit = 0; bit < 10; ++bit)
        for (uint32_t axis = 0; axis < 3; ++axis) m |= uint64_t((v >> (10 * axis + bit)) & 1u) << (3 * bit + axis);
      return m;
    };
    return morton(l) < morton(r);
  }));
  // An exception from a worker thread reaches the caller (an escaped one would end the program).
  const FailingSphere failing;
  CHECK_THROWS_WITH(BuildSVS(failing, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, 1), "no distance past x = 0.5");
  CHECK_THROWS_WITH(BuildSBS(failing, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, 4, 1), "no distance past x = 0.5");
  CHECK_THROWS_WITH(BuildGrid(failing, float3(-1.0f, -1.0f, -1.0f), 2.0f, 17), "no distance past x = 0.5");
}

TEST_CASE("SDF: a memory budget picks the deepest sparse voxel set that fits", "[sdf]")
{
  const SdfSphere sphere(float3(0.0f, 0.0f, 0.0f), 0.7f);
  const float3 boxMin(-1.0f, -1.0f, -1.0f);
  const size_t depth5 = BuildSVS(sphere, boxMin, 2.0f, 5, 1).Bytes(), depth6 = BuildSVS(sphere, boxMin, 2.0f, 6, 1).Bytes();
  REQUIRE(depth5 < depth6);
  CHECK(BuildSVSWithinBudget(sphere, boxMin, 2.0f, 8, 1, depth6 - 1).depth == 5);
  CHECK(BuildSVSWithinBudget(sphere, boxMin, 2.0f, 8, 1, depth6).depth == 6);
  CHECK(BuildSVSWithinBudget(sphere, boxMin, 2.0f, 5, 1, size_t(1) << 30).depth == 5);  // the depth limit holds
  CHECK_THROWS_WITH(BuildSVSWithinBudget(sphere, boxMin, 2.0f, 8, 1, 4), "no sparse voxel set of this SDF fits in 4 bytes, not even at depth 1");
}

TEST_CASE("SDF: rays hit the sparse voxel and brick sets where the exact surface is", "[sdf]")
{
  // Sphere of radius 0.7 in [-1, 1]^3 at depth 5: voxels of 1/16. The trilinear interpolant of the
  // exact distance errs by O(h^2 / R) = 0.006; the bound, with quantisation: 0.01.
  const float radius = 0.7f;
  const SdfSphere sphere(float3(0.0f, 0.0f, 0.0f), radius);
  for (uint32_t bytes : {1u, 2u, 4u}) {
    const SdfSVS svs = BuildSVS(sphere, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, bytes);
    const RayStats s = SphereRays([&](float3 o, float3 d) { return TraceSVS(svs, o, d, 0.0f, 1e9f, 8); }, radius, 1.0f, 200, 3);
    INFO("SVS, " << bytes << " bytes: " << s.misses << " misses, max error " << s.maxError << ", min normal dot " << s.minNormalDot);
    CHECK(s.misses == 0);
    CHECK(s.maxError < 0.01f);
    CHECK(s.minNormalDot > 0.99f);
  }
  for (uint32_t brick : {2u, 4u, 8u}) {
    const SdfSBS sbs = BuildSBS(sphere, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, brick, 2);
    const RayStats s = SphereRays([&](float3 o, float3 d) { return TraceSBS(sbs, o, d, 0.0f, 1e9f, 8); }, radius, 1.0f, 200, 4);
    INFO("SBS, bricks of " << brick << ": " << s.misses << " misses, max error " << s.maxError);
    CHECK(s.misses == 0);
    CHECK(s.maxError < 0.01f);
    CHECK(s.minNormalDot > 0.99f);
  }
  // More Newton iterations: no larger error (the iteration count is a knob).
  const SdfSVS svs = BuildSVS(sphere, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, 4);
  const RayStats one = SphereRays([&](float3 o, float3 d) { return TraceSVS(svs, o, d, 0.0f, 1e9f, 1); }, radius, 1.0f, 100, 5);
  const RayStats eight = SphereRays([&](float3 o, float3 d) { return TraceSVS(svs, o, d, 0.0f, 1e9f, 8); }, radius, 1.0f, 100, 5);
  INFO("max error with 1 Newton iteration " << one.maxError << ", with 8 " << eight.maxError);
  CHECK(eight.maxError <= one.maxError);
}

TEST_CASE("SDF: rays along voxel faces, edges and corners do not leak through", "[sdf]")
{
  // Rays parallel to the axes through the grid's planes, lines and vertices, at a rounded box and a
  // sphere: every ray aimed inside the shape's silhouette hits.
  const SdfRoundedBox box(float3(0.0f, 0.0f, 0.0f), float3(0.55f, 0.45f, 0.5f), 0.1f);
  const SdfSphere sphere(float3(0.0f, 0.0f, 0.0f), 0.6f);
  const float h = 2.0f / 32.0f;
  for (const ISdf* shape : {static_cast<const ISdf*>(&box), static_cast<const ISdf*>(&sphere)}) {
    const SdfSVS svs = BuildSVS(*shape, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, 2);
    const SdfSBS sbs = BuildSBS(*shape, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, 4, 2);
    int rays = 0, leaks = 0;
    for (int axis = 0; axis < 3; ++axis)
      for (int i = -5; i <= 5; ++i)
        for (int j = -5; j <= 5; ++j)
          for (float offset : {0.0f, 0.5f * h}) {  // on grid lines (edges, corners), and on faces only
            float3 origin(0.0f, 0.0f, 0.0f), dir(0.0f, 0.0f, 0.0f);
            const float a = float(i) * h + offset, b = float(j) * h;
            origin[axis] = -3.0f;
            origin[(axis + 1) % 3] = a;
            origin[(axis + 2) % 3] = b;
            dir[axis] = 1.0f;
            if (SphereTrace(*shape, origin, dir, 0.0f, 10.0f, 1e-5f, 256) < 0.0f) continue;  // misses the shape
            ++rays;
            leaks += TraceSVS(svs, origin, dir, 0.0f, 10.0f, 8).t < 0.0f;
            leaks += TraceSBS(sbs, origin, dir, 0.0f, 10.0f, 8).t < 0.0f;
          }
    INFO(rays << " axis-aligned rays, " << leaks << " leaks");
    CHECK(rays > 300);
    CHECK(leaks == 0);
  }
}

TEST_CASE("SDF: inside starts, tmin and tmax inside a voxel, NaN and inf rays", "[sdf]")
{
  const SdfSphere sphere(float3(0.0f, 0.0f, 0.0f), 0.7f);
  const SdfSVS svs = BuildSVS(sphere, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, 2);
  const float3 origin(0.0f, 0.0f, -2.0f), dir(0.0f, 0.0f, 1.0f);
  const float exact = 1.3f;
  // From inside: a hit before the ray could leave (a shadow ray from inside is blocked). Where the
  // start's voxel is stored (near the surface), at the start itself.
  const float3 deep(0.1f, 0.2f, 0.0f);
  const SdfHit inside = TraceSVS(svs, deep, dir, 0.0f, 10.0f, 8);
  CHECK(inside.t >= 0.0f);
  CHECK(inside.t < std::sqrt(0.49f - 0.05f));  // where it leaves the sphere
  const float3 nearSurface(0.0f, 0.0f, -0.695f);  // in the stored voxel z in [-0.75, -0.6875]
  CHECK(TraceSVS(svs, nearSurface, dir, 0.0f, 10.0f, 8).t == Approx(0.0f).margin(1e-6));
  // tmax ending inside the voxel before the surface: no hit; just past it: the hit.
  CHECK(TraceSVS(svs, origin, dir, 0.0f, exact - 0.01f, 8).t < 0.0f);
  CHECK(TraceSVS(svs, origin, dir, 0.0f, exact + 0.01f, 8).t == Approx(exact).margin(0.01));
  // tmin starting inside the voxel before the surface: the same hit; past the far side: none.
  CHECK(TraceSVS(svs, origin, dir, exact - 0.02f, 10.0f, 8).t == Approx(exact).margin(0.01));
  CHECK(TraceSVS(svs, origin, dir, 2.0f + 0.75f, 10.0f, 8).t < 0.0f);
  // tmin == tmax inside the voxel just before the surface: no hit (no root may leave the interval).
  CHECK(TraceSVS(svs, origin, dir, exact - 0.02f, exact - 0.02f, 8).t < 0.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (float3 d : {float3(nan, 0.0f, 1.0f), float3(0.0f, 0.0f, nan), float3(inf, 0.0f, 1.0f), float3(0.0f, 0.0f, 0.0f)})
    CHECK(TraceSVS(svs, origin, d, 0.0f, 10.0f, 8).t < 0.0f);
  CHECK(TraceSVS(svs, float3(nan, 0.0f, -2.0f), dir, 0.0f, 10.0f, 8).t < 0.0f);
  CHECK(TraceSVS(svs, origin, dir, nan, 10.0f, 8).t < 0.0f);
  CHECK(SphereTrace(sphere, origin, float3(nan, nan, nan), 0.0f, 10.0f, 1e-5f, 64) < 0.0f);
}

TEST_CASE("SDF: scales from 1e-3 to 1e3 keep the relative error", "[sdf]")
{
  for (float scale : {1e-3f, 1.0f, 1e3f}) {
    const float radius = 0.7f * scale;
    const SdfSphere sphere(float3(0.0f, 0.0f, 0.0f), radius);
    const SdfSVS svs = BuildSVS(sphere, float3(-scale, -scale, -scale), 2.0f * scale, 5, 2);
    const RayStats s = SphereRays([&](float3 o, float3 d) { return TraceSVS(svs, o, d, 0.0f, 1e9f, 8); }, radius, scale, 100, 6);
    INFO("scale " << scale << ": " << s.misses << " misses, max error / scale " << s.maxError);
    CHECK(s.misses == 0);
    CHECK(s.maxError < 0.01f);
  }
}

TEST_CASE("SDF: sphere tracing the analytic shapes and the dense grid", "[sdf]")
{
  const SdfSphere sphere(float3(0.0f, 0.0f, 0.0f), 0.7f);
  const SdfGrid grid = BuildGrid(sphere, float3(-1.0f, -1.0f, -1.0f), 2.0f, 65);
  CHECK(grid.Bytes() == 65u * 65u * 65u * 4u);
  const auto analytic = SphereRays([&](float3 o, float3 d) { return SdfHit{SphereTrace(sphere, o, d, 0.0f, 10.0f, 1e-5f, 256), LiteMath::normalize(o)}; },
                                   0.7f, 1.0f, 100, 7);
  CHECK(analytic.misses == 0);
  CHECK(analytic.maxError < 1e-4f);
  const auto sampled = SphereRays([&](float3 o, float3 d) { return SdfHit{SphereTraceGrid(grid, o, d, 0.0f, 10.0f, 1e-5f, 256), LiteMath::normalize(o)}; },
                                  0.7f, 1.0f, 100, 7);
  CHECK(sampled.misses == 0);
  CHECK(sampled.maxError < 0.01f);
  // The other analytic shapes: a hit from outside lands on their surface.
  const SdfTorus torus(float3(0.0f, 0.0f, 0.0f), 0.6f, 0.2f);
  const float t = SphereTrace(torus, float3(0.6f, 0.0f, -2.0f), float3(0.0f, 0.0f, 1.0f), 0.0f, 10.0f, 1e-5f, 256);
  CHECK(t == Approx(2.0f - std::sqrt(0.8f * 0.8f - 0.6f * 0.6f)).margin(1e-4));  // the tube's near side at x = 0.6
  const SdfBox box(float3(0.0f, 0.0f, 0.0f), float3(0.5f, 0.5f, 0.5f));
  CHECK(box.Distance(float3(1.0f, 0.0f, 0.0f)) == Approx(0.5f));
  CHECK(box.Distance(float3(0.0f, 0.0f, 0.0f)) == Approx(-0.5f));
}

TEST_CASE("SDF: the Mandelbulb builds a sparse voxel set that rays hit near its surface", "[sdf]")
{
  const SdfMandelbulb bulb(float3(0.0f, 0.0f, 0.0f), 1.0f);
  SdfBuildStats stats;
  const SdfSVS svs = BuildSVS(bulb, float3(-1.5f, -1.5f, -1.5f), 3.0f, 5, 2, &stats);
  INFO("kept " << stats.voxelsKept << " of " << stats.voxelsCrossable << " crossable voxels");
  REQUIRE(svs.VoxelCount() > 100);
  std::mt19937 rng(8);
  int hits = 0;
  for (int i = 0; i < 50; ++i) {
    const float3 origin = 3.0f * RandomUnit(rng), dir = LiteMath::normalize(-origin);
    const SdfHit h = TraceSVS(svs, origin, dir, 0.0f, 10.0f, 8);
    if (h.t < 0.0f) continue;
    ++hits;
    // The hit is within a voxel diagonal of where the estimator says the surface is.
    CHECK(std::fabs(bulb.Distance(origin + h.t * dir)) < std::sqrt(3.0f) * svs.VoxelSize());
  }
  CHECK(hits > 40);  // rays at the centre hit the bulb's body
}

// ---- Meshes: exact distance, robust sign ----
#include "SdfMesh.h"

#include <map>

namespace {

struct Mesh {
  std::vector<float3> vertices;
  std::vector<uint32_t> indices;
};

// An icosahedron subdivided `levels` times onto the sphere of `radius`: closed, outward-facing.
Mesh Icosphere(float radius, int levels) {
  const float g = (1.0f + std::sqrt(5.0f)) * 0.5f;
  Mesh m;
  for (float3 v : {float3(-1, g, 0), float3(1, g, 0), float3(-1, -g, 0), float3(1, -g, 0), float3(0, -1, g), float3(0, 1, g),
                   float3(0, -1, -g), float3(0, 1, -g), float3(g, 0, -1), float3(g, 0, 1), float3(-g, 0, -1), float3(-g, 0, 1)})
    m.vertices.push_back(radius * LiteMath::normalize(v));
  m.indices = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,
               3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> middle;
    auto mid = [&](uint32_t a, uint32_t b) {
      auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = middle.find(key);
      if (it != middle.end()) return it->second;
      m.vertices.push_back(radius * LiteMath::normalize(m.vertices[a] + m.vertices[b]));
      return middle[key] = uint32_t(m.vertices.size() - 1);
    };
    std::vector<uint32_t> next;
    for (size_t t = 0; t < m.indices.size(); t += 3) {
      const uint32_t a = m.indices[t], b = m.indices[t + 1], c = m.indices[t + 2];
      const uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    m.indices = next;
  }
  return m;
}

// A torus around the y axis, `u` segments around it and `v` around the tube: closed, not convex.
Mesh TorusMesh(float major, float minor, uint32_t u, uint32_t v) {
  Mesh m;
  for (uint32_t i = 0; i < u; ++i)
    for (uint32_t j = 0; j < v; ++j) {
      const float a = 2.0f * float(LiteMath::M_PI) * float(i) / float(u), b = 2.0f * float(LiteMath::M_PI) * float(j) / float(v);
      const float r = major + minor * std::cos(b);
      m.vertices.push_back(float3(r * std::cos(a), minor * std::sin(b), r * std::sin(a)));
    }
  for (uint32_t i = 0; i < u; ++i)
    for (uint32_t j = 0; j < v; ++j) {
      const uint32_t p = i * v + j, q = ((i + 1) % u) * v + j, r = i * v + (j + 1) % v, s = ((i + 1) % u) * v + (j + 1) % v;
      m.indices.insert(m.indices.end(), {p, r, q, q, r, s});
    }
  return m;
}

// A cube [-h, h]^3 of 12 triangles: sharp edges and corners.
Mesh CubeMesh(float h) {
  Mesh m;
  for (uint32_t c = 0; c < 8; ++c) m.vertices.push_back(float3(c & 1 ? h : -h, c & 2 ? h : -h, c & 4 ? h : -h));
  m.indices = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  for (size_t t = 0; t < m.indices.size(); t += 3) {  // each face outward: its normal away from the centre
    const float3 a = m.vertices[m.indices[t]], b = m.vertices[m.indices[t + 1]], c = m.vertices[m.indices[t + 2]];
    if (LiteMath::dot(LiteMath::cross(b - a, c - a), a + b + c) < 0.0f) std::swap(m.indices[t + 1], m.indices[t + 2]);
  }
  return m;
}

// Counts the samples of a 17^3 grid over [-1, 1]^3 where the sign of sdf.Distance disagrees with
// the exact winding number, leaving out those where the winding number is within 1/4 of 1/2 (on
// the surface, or in a hole's mouth: no side to agree on).
struct SignAgreement {
  int samples = 0, disagreements = 0;
};
SignAgreement AgreeWithWindingNumber(const SdfMesh& sdf) {
  SignAgreement a;
  for (int z = 0; z < 17; ++z)
    for (int y = 0; y < 17; ++y)
      for (int x = 0; x < 17; ++x) {
        // Grid samples, offset so that some fall on the meshes' planes and edges.
        const float3 p = float3(-1.0f, -1.0f, -1.0f) + 0.125f * float3(float(x), float(y), float(z));
        const float winding = sdf.WindingNumber(p);
        if (std::fabs(winding - 0.5f) < 0.25f) continue;
        ++a.samples;
        a.disagreements += (sdf.Distance(p) < 0.0f) != (winding > 0.5f);
      }
  return a;
}

// An icosphere with the cap above `capAngle` radians from +z cut away: a scan's hole.
Mesh HoledSphere(float radius, float capAngle) {
  Mesh m = Icosphere(radius, 3);
  std::vector<uint32_t> kept;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const float3 centroid = (m.vertices[m.indices[t]] + m.vertices[m.indices[t + 1]] + m.vertices[m.indices[t + 2]]) / 3.0f;
    if (centroid.z < radius * std::cos(capAngle)) kept.insert(kept.end(), {m.indices[t], m.indices[t + 1], m.indices[t + 2]});
  }
  m.indices = kept;
  return m;
}

// Two cubes of half-size h that share one edge (its two vertices and the edge itself): the edge
// has four triangles, and its pseudo-normal, their sum, is zero.
Mesh CubesSharingAnEdge(float h) {
  Mesh m = CubeMesh(h);
  const Mesh second = CubeMesh(h);
  // The second cube sits at (2h, 2h, 0): its corners with x = y = -h are the first's with x = y = h.
  std::vector<uint32_t> index(8);
  for (uint32_t c = 0; c < 8; ++c) {
    const float3 v = second.vertices[c] + float3(2.0f * h, 2.0f * h, 0.0f);
    index[c] = uint32_t(m.vertices.size());
    for (uint32_t k = 0; k < 8; ++k)
      if (LiteMath::length(m.vertices[k] - v) == 0.0f) index[c] = k;
    if (index[c] == m.vertices.size()) m.vertices.push_back(v);
  }
  for (uint32_t i : second.indices) m.indices.push_back(index[i]);
  return m;
}

}  // namespace

TEST_CASE("SDF from a mesh: exact distances, and the sign agrees with the winding number everywhere", "[sdf][mesh]")
{
  for (const Mesh& mesh : {Icosphere(0.7f, 3), TorusMesh(0.6f, 0.25f, 48, 24), CubeMesh(0.5f)})
    for (SdfSign sign : {SdfSign::Auto, SdfSign::WindingNumber}) {
      const SdfMesh sdf(mesh.vertices, mesh.indices, sign);
      CHECK(sdf.OpenOrNonManifoldEdges() == 0);
      CHECK(sdf.Sign() == (sign == SdfSign::Auto ? SdfSign::PseudoNormal : SdfSign::WindingNumber));
      const SignAgreement a = AgreeWithWindingNumber(sdf);
      INFO(sdf.TriangleCount() << " triangles, sign " << int(sdf.Sign()) << ": " << a.disagreements << " of " << a.samples << " samples disagree");
      CHECK(a.samples > 4000);
      CHECK(a.disagreements == 0);
    }
  // Exact distances: the cube against the analytic box, at its edges and corners from both sides.
  const SdfMesh cube(CubeMesh(0.5f).vertices, CubeMesh(0.5f).indices);
  const SdfBox box(float3(0.0f, 0.0f, 0.0f), float3(0.5f, 0.5f, 0.5f));
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-0.8f, 0.8f);
  for (int i = 0; i < 2000; ++i) {
    const float3 p(u(rng), u(rng), u(rng));
    REQUIRE(cube.Distance(p) == Approx(box.Distance(p)).margin(1e-5));
  }
  for (float e : {1e-4f, -1e-4f})
    for (float3 p : {float3(0.5f, 0.5f, 0.1f), float3(0.5f, 0.5f, 0.5f), float3(-0.5f, 0.5f, -0.5f), float3(0.5f, -0.2f, -0.5f)}) {
      const float3 q = p + e * LiteMath::normalize(p);  // just outside (e > 0) or inside an edge or corner
      INFO("(" << q.x << ", " << q.y << ", " << q.z << ")");
      CHECK((cube.Distance(q) > 0.0f) == (e > 0.0f));
    }
  CHECK_THROWS_WITH(SdfMesh({float3(0, 0, 0)}, {0, 0}), "a mesh needs triangles: three indices each");
  CHECK_THROWS_WITH(SdfMesh({float3(0, 0, 0)}, {0, 0, 1}), "a triangle index is out of the vertices' range");
}

TEST_CASE("SDF from a mesh with a hole or a non-manifold edge: the fast winding number gives the sign", "[sdf][mesh]")
{
  for (const Mesh& mesh : {HoledSphere(0.7f, 0.8f), CubesSharingAnEdge(0.4f)}) {
    const SdfMesh sdf(mesh.vertices, mesh.indices);  // Auto
    INFO(sdf.TriangleCount() << " triangles, " << sdf.OpenOrNonManifoldEdges() << " edges without exactly two faces");
    CHECK(sdf.OpenOrNonManifoldEdges() > 0);
    REQUIRE(sdf.Sign() == SdfSign::WindingNumber);
    const SignAgreement a = AgreeWithWindingNumber(sdf);
    INFO(a.disagreements << " of " << a.samples << " samples disagree");
    CHECK(a.samples > 4000);
    CHECK(a.disagreements == 0);
    // The distance itself does not depend on the sign's source.
    const SdfMesh pseudo(mesh.vertices, mesh.indices, SdfSign::PseudoNormal);
    for (float3 p : {float3(0.1f, 0.2f, 0.9f), float3(-0.3f, 0.0f, 0.1f), float3(0.4f, 0.4f, 0.0f)})
      CHECK(std::fabs(sdf.Distance(p)) == std::fabs(pseudo.Distance(p)));
  }
  // Pseudo-normals read the holed sphere's mouth wrongly: above a wide hole, outside, the nearest
  // point is on the hole's rim, whose face leans outwards, so the point seems behind it.
  const Mesh holed = HoledSphere(0.7f, 0.8f);
  const SdfMesh pseudo(holed.vertices, holed.indices, SdfSign::PseudoNormal);
  CHECK(AgreeWithWindingNumber(pseudo).disagreements > 0);
}

TEST_CASE("SDF from a mesh: a vertex at inf or NaN is refused with std::invalid_argument, not built", "[sdf][mesh]")
{
  for (float bad : {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()}) {
    Mesh m = Icosphere(1.0f, 1);
    m.vertices[m.indices[4]].y = bad;
    try {
      litesdf::SdfMesh mesh(m.vertices, m.indices);
      FAIL("a vertex at " << bad << " was accepted");
    } catch (const std::invalid_argument& e) {
      CHECK(std::string(e.what()).find("not finite") != std::string::npos);
    }
    std::vector<float> positions = {0, 0, 0, 1, 0, 0, 0, bad, 0};
    CHECK_THROWS_AS(litesdf::FitIntoCube(positions, 1.0f), std::invalid_argument);
  }
}

TEST_CASE("SDF from a mesh: the fast winding number stays near the exact one", "[sdf][mesh]")
{
  const Mesh torus = TorusMesh(0.6f, 0.25f, 48, 24);
  const SdfMesh sdf(torus.vertices, torus.indices, SdfSign::WindingNumber);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-1.2f, 1.2f);
  float worst = 0.0f;
  for (int i = 0; i < 3000; ++i) {
    const float3 p(u(rng), u(rng), u(rng));
    worst = std::max(worst, std::fabs(sdf.FastWindingNumber(p) - sdf.WindingNumber(p)));
  }
  INFO("largest difference " << worst);
  CHECK(worst < 0.05f);  // the sign is read against 1/2
  CHECK(worst > 0.0f);   // it did take the dipoles: the clusters are in use
  // Far away the whole mesh is one dipole, whose moment a closed mesh cancels: 0 exactly.
  CHECK(std::fabs(sdf.FastWindingNumber(float3(50.0f, 3.0f, -7.0f))) < 1e-6f);
}

TEST_CASE("SDF from a mesh: a sparse voxel set of a tessellated sphere traces like the sphere", "[sdf][mesh]")
{
  const Mesh mesh = Icosphere(0.7f, 4);  // 5120 triangles: deviates from the sphere by under 0.002
  const SdfMesh sdf(mesh.vertices, mesh.indices);
  SdfBuildStats stats;
  const SdfSVS svs = BuildSVS(sdf, float3(-1.0f, -1.0f, -1.0f), 2.0f, 5, 2, &stats);
  INFO("kept " << stats.voxelsKept << " voxels in " << stats.milliseconds << " ms");
  const RayStats s = SphereRays([&](float3 o, float3 d) { return TraceSVS(svs, o, d, 0.0f, 1e9f, 8); }, 0.7f, 1.0f, 200, 10);
  INFO(s.misses << " misses, max error " << s.maxError << ", min normal dot " << s.minNormalDot);
  CHECK(s.misses == 0);
  CHECK(s.maxError < 0.012f);
  CHECK(s.minNormalDot > 0.98f);
}

TEST_CASE("SDF: the BVH over voxels and bricks finds the hits the reference loops find", "[sdf]")
{
  const SdfTorus torus(float3(0.0f, 0.0f, 0.0f), 0.6f, 0.25f);
  const SdfSVS svs = BuildSVS(torus, float3(-1.0f, -1.0f, -1.0f), 2.0f, 6, 2);
  const SdfSBS sbs = BuildSBS(torus, float3(-1.0f, -1.0f, -1.0f), 2.0f, 6, 4, 1);
  const BVHTree svsTree = BuildSdfBVH(svs), sbsTree = BuildSdfBVH(sbs);
  REQUIRE(svsTree.primIndices.size() == svs.VoxelCount());
  REQUIRE(sbsTree.primIndices.size() == sbs.BrickCount());
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  int hits = 0;
  for (int i = 0; i < 300; ++i) {
    const float3 origin = 2.5f * RandomUnit(rng), dir = LiteMath::normalize(0.8f * float3(u(rng), u(rng), u(rng)) - origin);
    const SdfHit a = TraceSVS(svs, origin, dir, 0.0f, 10.0f, 8), b = TraceSVS(svs, svsTree, origin, dir, 0.0f, 10.0f, 8);
    const SdfHit c = TraceSBS(sbs, origin, dir, 0.0f, 10.0f, 8), d = TraceSBS(sbs, sbsTree, origin, dir, 0.0f, 10.0f, 8);
    REQUIRE(b.t == Approx(a.t).margin(1e-6));  // the same voxel's root; the bracket may differ in its far end
    REQUIRE(d.t == Approx(c.t).margin(1e-6));
    hits += a.t >= 0.0f;
  }
  CHECK(hits > 100);
  // No voxels: no tree, no hit.
  const SdfSVS empty = BuildSVS(SdfSphere(float3(5.0f, 5.0f, 5.0f), 0.1f), float3(-1.0f, -1.0f, -1.0f), 2.0f, 4, 2);
  CHECK(TraceSVS(empty, BuildSdfBVH(empty), float3(0.0f, 0.0f, -2.0f), float3(0.0f, 0.0f, 1.0f), 0.0f, 10.0f, 8).t < 0.0f);
}
