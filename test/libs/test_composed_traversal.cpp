// The BVH traversal translated by composition (PrimaryRays_CPU, _ISPC and _Vulkan, which compose
// ISceneObject=BVHScene) against BVHScene as written, on the numerical extremes of
// test_bvh_extremes.cpp: rays through the edges and vertices of closed meshes, tiny, huge and
// far-away scenes, axis-parallel rays with +0 and -0 components, degenerate triangles, one shared
// centre, 0, 1 and 2 triangles, instances, and invalid rays; and signed distance fields (grid, SVS,
// SBS) at their own extremes.
//
// _CPU runs the very same compiled traversal on all cores: its hits must be bit-identical. So must
// _ISPC's, one ray a SIMD lane (where ISPC is found): it computes without fused multiply-adds, its
// fma is exact as std::fma, and its min and max compare as C++'s do (LiteMath.isph).
// _Vulkan must give the same primId for at least 99.99% of the rays, counting ties as the same: a
// ray aimed exactly at a vertex or an edge hits several triangles at the same distance, and a
// last-ulp difference picks another of them (it must contain the hit point). And t must lie within
// 1e-5 * (t + |origin| + scene size), about 80 ulps of the largest magnitude in the computation and
// far below the distance between neighbouring triangles, so a wrong triangle cannot pass. The
// shaders multiply and add without fusing (NoContraction), as the CPU does: fused, a shared edge's
// two functions are no longer exact negatives and rays leak between triangles (seen on an H100).
// A GPU's division is only within 2.5 ulp, though, and the ray's shear constants are quotients: on
// devices that do not round like the CPU (RoundsLikeTheCpu) 99.9% and 0.1% of rays outside the
// tolerance are allowed, as for ray tracing hardware, whose own triangle test differs anyway.
// On a device with ray queries (CTest's hw variants) PrimaryRays_Vulkan traces on them instead, and
// rays through edges and vertices may also miss there (RequireAgreement); the sw variants hide ray
// queries (CROSSRT_DEVICE_FEATURES), so the translated traversal runs as on any other device.
#include <catch2/catch.hpp>

#include "PrimaryRays.h"
#include "PrimaryRays_CPU.h"
#include "PrimaryRays_Vulkan.h"
#ifdef CROSSRT_HAS_ISPC
#include "PrimaryRays_ISPC.h"
#endif
#include "SdfStructures.h"
#include "TestMeshes.h"
#include "TestSupport.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <set>
#include <sstream>

using namespace LiteMath;

namespace {

constexpr uint32_t kMiss = 0xFFFFFFFFu;

struct Rays
{
  std::vector<float4> posAndNear, dirAndFar;
  void Add(float3 org, float3 dir, float tnear = 0.0f, float tfar = 1e30f)
  {
    posAndNear.push_back(float4(org.x, org.y, org.z, tnear));
    dirAndFar.push_back(float4(dir.x, dir.y, dir.z, tfar));
  }
  size_t Size() const { return posAndNear.size(); }
};

std::vector<CRT_Hit> Cast(PrimaryRays& renderer, const std::shared_ptr<ISceneObject>& scene, const Rays& rays)
{
  renderer.SetScene(scene, {}, {});
  renderer.CommitDeviceData();
  std::vector<CRT_Hit> hits(rays.Size());
  renderer.CastRays(rays.posAndNear.data(), rays.dirAndFar.data(), hits.data(), int(rays.Size()));
  return hits;
}

// Distance from p to triangle (a, b, c) (closest-point regions, Ericson 2005, 5.1.5).
float DistanceToTriangle(float3 p, float3 a, float3 b, float3 c)
{
  const float3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return length(p - a);
  const float3 bp = p - b;
  const float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0f && d4 <= d3) return length(p - b);
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return length(p - (a + ab * (d1 / (d1 - d3))));
  const float3 cp = p - c;
  const float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0f && d5 <= d6) return length(p - c);
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return length(p - (a + ac * (d2 / (d2 - d6))));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) return length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  const float denom = 1.0f / (va + vb + vc);
  return length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

struct Outcome
{
  std::vector<CRT_Hit> original, cpu, vulkan;
  bool hasVulkan = false;
};

// The agreement stated at the top of this file, of `gpu` hits with the original's.
// On ray tracing hardware (`exact` false) a ray through an edge or a vertex may miss where the
// original hits (`edgeMisses`: up to `edgeMissShare` of the rays, and one ray in any case): an edge
// no other triangle shares, or one a ray runs along, is half-open under Vulkan's tie rule, and
// lavapipe's test is not watertight even where edges are shared (driver.ray_triangle_watertight).
// A miss anywhere else counts against the agreement.
void RequireAgreement(const char* what, const std::vector<CRT_Hit>& original, const std::vector<CRT_Hit>& gpu, const Rays& rays,
                      float sceneSize, const TriangleMesh* mesh, bool exact, double edgeMissShare = 0.02)
{
  size_t samePrim = 0, ties = 0, tOutside = 0, idsDiffer = 0, missed = 0, edgeMisses = 0, extra = 0;
  std::ostringstream firstOther;  // the first ray on another triangle that is no tie
  for (size_t i = 0; i < rays.Size(); ++i)
  {
    const CRT_Hit &o = original[i], &v = gpu[i];
    if (o.primId != kMiss && v.primId == kMiss)
    {
      const float u = o.coords[0], w = o.coords[1];
      const bool onEdge = std::min({u, w, 1.0f - u - w}) <= 1e-4f;
      missed += !onEdge;
      edgeMisses += onEdge;
    }
    extra += o.primId == kMiss && v.primId != kMiss;
    samePrim += o.primId == v.primId;
    idsDiffer += o.primId == v.primId && (o.instId != v.instId || o.geomId != v.geomId);
    const float3 org = to_float3(rays.posAndNear[i]), dir = to_float3(rays.dirAndFar[i]);
    const float tolerance = 1e-5f * (std::fabs(o.t) + length(org) + sceneSize);
    if (o.primId == kMiss || v.primId == kMiss)
      continue;
    tOutside += !(std::fabs(o.t - v.t) <= tolerance);
    if (o.primId != v.primId && mesh)
    {
      const uint32_t* tri = &mesh->indices[3 * v.primId];
      const float3 p = org + dir * v.t;
      const bool tie = DistanceToTriangle(p, Vertex(*mesh, tri[0]), Vertex(*mesh, tri[1]), Vertex(*mesh, tri[2])) <= tolerance * length(dir) &&
                       DistanceToTriangle(p, Vertex(*mesh, mesh->indices[3 * o.primId]), Vertex(*mesh, mesh->indices[3 * o.primId + 1]),
                                          Vertex(*mesh, mesh->indices[3 * o.primId + 2])) <= tolerance * length(dir);
      ties += tie;
      if (!tie && firstOther.str().empty())
        firstOther << "the first on another triangle: ray " << i << " primId " << o.primId << " t " << o.t << " vs " << v.primId << " t " << v.t;
    }
  }
  INFO(what << ": " << samePrim << " of " << rays.Size() << " rays on the original's primId, " << ties
            << " more on another triangle at the same point; " << tOutside << " t outside the tolerance; " << edgeMisses
            << " missed through an edge or vertex and " << missed << " elsewhere where the original hit, " << extra
            << " hit where it missed; " << firstOther.str());
  if (exact)
  {
    REQUIRE(double(samePrim + ties) >= 0.9999 * double(rays.Size()));
    REQUIRE(tOutside == 0);
  }
  else  // the ray's shear constants are quotients: a GPU's may differ in the last bit (RoundsLikeTheCpu)
  {
    REQUIRE(double(edgeMisses) <= std::max(1.0, edgeMissShare * double(rays.Size())));
    REQUIRE(double(samePrim + ties + edgeMisses) >= 0.999 * double(rays.Size()));
    REQUIRE(double(tOutside) <= 0.001 * double(rays.Size()));
  }
  REQUIRE(idsDiffer == 0);
}

// Traces the rays with BVHScene as written, PrimaryRays_CPU and PrimaryRays_Vulkan (validation on)
// running BVHScene's translated traversal, and on a device with ray queries also on its ray
// tracing hardware; checks the agreement stated at the top of this file.
// `mesh`, when given, is the scene's only geometry with one identity instance: ties are checked on it.
Outcome TraceEverywhere(const std::shared_ptr<ISceneObject>& scene, const Rays& rays, float sceneSize,
                        const TriangleMesh* mesh = nullptr, bool exports = true, double edgeMissShare = 0.02)
{
  Outcome out;
  for (size_t i = 0; i < rays.Size(); ++i)
    out.original.push_back(scene->RayQuery_NearestHit(rays.posAndNear[i], rays.dirAndFar[i]));
  auto cpu = CreatePrimaryRays_CPU(1, 1);
  out.cpu = Cast(*cpu, scene, rays);
  REQUIRE(std::memcmp(out.cpu.data(), out.original.data(), sizeof(CRT_Hit) * rays.Size()) == 0);
#ifdef CROSSRT_HAS_ISPC
  {
    auto ispc = CreatePrimaryRays_ISPC(1, 1);
    const std::vector<CRT_Hit> lanes = Cast(*ispc, scene, rays);
    RequireAgreement("ISPC traversal", out.original, lanes, rays, sceneSize, mesh, true);
    size_t bitIdentical = 0, first = rays.Size();
    for (size_t i = 0; i < rays.Size(); ++i)
      if (std::memcmp(&lanes[i], &out.original[i], sizeof(CRT_Hit)) == 0)
        ++bitIdentical;
      else if (first == rays.Size())
        first = i;
    INFO(bitIdentical << " of " << rays.Size() << " ISPC hits bit-identical to the original's");
    std::ostringstream firstDiffering;
    if (first < rays.Size())
      firstDiffering << "the first differs: ray " << first << ", t " << std::hexfloat << out.original[first].t << " vs " << lanes[first].t
                     << ", u " << out.original[first].coords[0] << " vs " << lanes[first].coords[0] << std::defaultfloat << ", primId "
                     << out.original[first].primId << " vs " << lanes[first].primId;
    INFO(firstDiffering.str());
    CHECK(bitIdentical == rays.Size());
  }
#endif

  auto ctx = ValidatedContext();
  if (!ctx)
    return out;
  auto vulkan = std::make_shared<PrimaryRays_Vulkan>(ctx, 1, 1);
  // A device with ray queries traces on them (CTest's hw variant); the translated traversal is what
  // every other device runs (the sw variant hides ray queries: CROSSRT_DEVICE_FEATURES).
  if (ctx->hasRayQuery && exports)
  {
    REQUIRE(vulkan->UsesRayTracingHardware());
    const std::vector<CRT_Hit> hardware = Cast(*vulkan, scene, rays);
    RequireNoValidationMessages(ctx);
    RequireAgreement("ray tracing hardware", out.original, hardware, rays, sceneSize, mesh, false, edgeMissShare);
    return out;
  }
  vulkan->UseRayTracingHardware(false);
  out.vulkan = Cast(*vulkan, scene, rays);
  out.hasVulkan = true;
  RequireNoValidationMessages(ctx);
  RequireAgreement("translated traversal", out.original, out.vulkan, rays, sceneSize, mesh, RoundsLikeTheCpu(*ctx));
  return out;
}

size_t Misses(const std::vector<CRT_Hit>& hits)
{
  size_t n = 0;
  for (const CRT_Hit& h : hits)
    n += h.primId == kMiss;
  return n;
}

}  // namespace

TEST_CASE("Translated traversal: rays from inside closed meshes through vertices and edges never miss", "[bvh][composition][device-features]")
{
  const char* impl = GENERATE(as<const char*>{}, "lbvh", "sah");
  INFO(impl);
  for (bool bumpy : {false, true})
  {
    INFO((bumpy ? "bumpy sphere" : "sphere"));
    const TriangleMesh mesh = bumpy ? BumpySphere(4) : Sphere(4);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::uniform_int_distribution<uint32_t> pick(0, uint32_t(mesh.indices.size() - 1));
    Rays rays;
    while (rays.Size() < 6000)
    {
      float3 org;
      do org = float3(u(rng), u(rng), u(rng)) * 0.6f;
      while (length(org) > 0.6f);
      const uint32_t t = pick(rng) / 3 * 3, corner = pick(rng) % 3;
      const float3 a = Vertex(mesh, mesh.indices[t + corner]), b = Vertex(mesh, mesh.indices[t + (corner + 1) % 3]);
      const int kind = int(rays.Size() % 3);
      const float3 target = kind == 0 ? org + float3(u(rng), u(rng), u(rng)) : kind == 1 ? a : 0.5f * (a + b);
      if (length(target - org) > 0.0f)
        rays.Add(org, target - org);
    }
    const Outcome o = TraceEverywhere(SceneOf(impl, mesh), rays, 2.6f, &mesh);
    REQUIRE(Misses(o.original) == 0);
    REQUIRE(Misses(o.cpu) == 0);
    if (o.hasVulkan)
      REQUIRE(Misses(o.vulkan) == 0);
  }
}

TEST_CASE("Translated traversal on tiny, huge and far-away scenes, and 1e6 sizes away", "[bvh][composition][device-features]")
{
  const TriangleMesh mesh = BumpySphere(5);  // 8192 triangles
  struct Placement { const char* what; float4x4 toWorld; float size; };
  const Placement placements[] = {
      {"unit", float4x4(), 1.3f},
      {"scaled by 1e-6", scale4x4(float3(1e-6f)), 1.3e-6f},
      {"scaled by 1e6", scale4x4(float3(1e6f)), 1.3e6f},
      {"moved 1000 sizes away", translate4x4(float3(1300.0f, -1300.0f, 1300.0f)), 1.3f},
      // Most triangles collapse there (test_bvh_extremes.cpp); the backends still trace the same
      // collapsed mesh alike.
      {"moved 1e6 sizes away", translate4x4(float3(1.3e6f, -1.3e6f, 1.3e6f)), 1.3f},
  };
  for (const Placement& p : placements)
  {
    INFO(p.what);
    const TriangleMesh placed = Transformed(mesh, p.toWorld);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    Rays rays;
    for (int i = 0; i < 20000; ++i)
    {
      const float3 from = to_float3(p.toWorld * float4(3.0f * u(rng), 3.0f * u(rng), 3.0f * u(rng), 1.0f));
      const float3 to = to_float3(p.toWorld * float4(u(rng), u(rng), u(rng), 1.0f));
      rays.Add(from, to - from);
    }
    const Outcome o = TraceEverywhere(SceneOf("lbvh", placed), rays, p.size, &placed);
    REQUIRE(Misses(o.original) < 15000);  // most rays aim at the mesh
  }
}

TEST_CASE("Translated traversal: axis-parallel rays with +0 and -0 direction components", "[bvh][composition][device-features]")
{
  const TriangleMesh cube = Cube();
  const float coords[] = {-1.5f, -1.0f, -0.5f, 0.0f, 0.25f, 0.5f, 1.0f, 1.5f};
  Rays rays;
  std::vector<bool> inside;
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {1.0f, -1.0f})
      for (float zero1 : {0.0f, -0.0f})
        for (float zero2 : {0.0f, -0.0f})
          for (float a : coords)
            for (float b : coords)
            {
              float org[3], dir[3];
              const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
              org[axis] = -5.0f * sign, org[a1] = a, org[a2] = b;
              dir[axis] = sign, dir[a1] = zero1, dir[a2] = zero2;
              rays.Add(float3(org[0], org[1], org[2]), float3(dir[0], dir[1], dir[2]), 0.0f, 100.0f);
              inside.push_back(std::fabs(a) <= 1.0f && std::fabs(b) <= 1.0f);
            }
  // Rays along the cube's edges and face diagonals: ties. A ray along an edge runs in one face's
  // plane and meets the other face exactly on its edge: on hardware (lavapipe) about half of them
  // miss, which Vulkan's tie rule allows.
  const Outcome o = TraceEverywhere(SceneOf("lbvh", cube), rays, 2.0f, &cube, true, 0.2);
  // Inside a face, its edges and corners included: a hit at distance exactly 4, on every backend.
  for (const auto* hits : {&o.original, &o.cpu, &o.vulkan})
    for (size_t i = 0; i < hits->size(); ++i)
    {
      INFO("ray " << i);
      REQUIRE(((*hits)[i].primId != kMiss) == inside[i]);
      if (inside[i])
        REQUIRE((*hits)[i].t == 4.0f);
    }
}

TEST_CASE("Translated traversal: degenerate triangles, one shared centre, 0, 1 and 2 triangles, instances, invalid rays", "[bvh][composition][device-features]")
{
  SECTION("zero-area triangles are never hit, and do not hide the others")
  {
    TriangleMesh mesh;
    mesh.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0.5f, 0.5f, 0, 2, 2, 0};
    mesh.indices = {3, 3, 3, 0, 2, 4, 1, 1, 2, 0, 1, 2};
    Rays rays;
    for (float x : {0.5f, 0.75f, 0.9f, 1.0f, 1.5f})
      rays.Add(float3(x, 0.5f * x, 1.0f), float3(0.0f, 0.0f, -1.0f), 0.0f, 10.0f);
    const Outcome o = TraceEverywhere(SceneOf("lbvh", mesh), rays, 3.0f);
    if (o.hasVulkan)
      for (size_t i = 0; i < rays.Size(); ++i)
        REQUIRE(o.vulkan[i].primId == (i < 4 ? 3u : kMiss));
  }
  SECTION("all triangles share one centre")
  {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    TriangleMesh mesh;
    for (uint32_t i = 0; i < 300; ++i)
    {
      const float3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c = -(a + b);
      mesh.positions.insert(mesh.positions.end(), {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z});
      mesh.indices.insert(mesh.indices.end(), {3 * i, 3 * i + 1, 3 * i + 2});
    }
    Rays rays;
    for (int i = 0; i < 10000; ++i)
    {
      const float3 from(3.0f * u(rng), 3.0f * u(rng), 3.0f * u(rng)), to(u(rng), u(rng), u(rng));
      rays.Add(from, to - from);
    }
    const char* impl = GENERATE(as<const char*>{}, "lbvh", "sah");
    INFO(impl);
    const Outcome o = TraceEverywhere(SceneOf(impl, mesh), rays, 2.0f, &mesh);
    REQUIRE(Misses(o.original) < 5000);
  }
  SECTION("0, 1 and 2 triangles")
  {
    TriangleMesh quad;
    quad.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    for (size_t triangles : {0, 1, 2})
    {
      INFO(triangles << " triangles");
      TriangleMesh mesh = quad;
      mesh.indices = {0, 1, 2, 0, 2, 3};
      mesh.indices.resize(3 * triangles);
      Rays rays;
      rays.Add(float3(0.75f, 0.25f, 1.0f), float3(0.0f, 0.0f, -1.0f), 0.0f, 10.0f);
      rays.Add(float3(0.25f, 0.75f, 1.0f), float3(0.0f, 0.0f, -1.0f), 0.0f, 10.0f);
      const Outcome o = TraceEverywhere(SceneOf("lbvh", mesh), rays, 1.0f);
      if (o.hasVulkan)
      {
        REQUIRE(o.vulkan[0].primId == (triangles >= 1 ? 0u : kMiss));
        REQUIRE(o.vulkan[1].primId == (triangles >= 2 ? 1u : kMiss));
      }
    }
  }
  SECTION("instances: the same mesh rotated, scaled and moved")
  {
    const TriangleMesh mesh = BumpySphere(4);
    const std::vector<float4x4> instances = {float4x4(), translate4x4(float3(3.0f, 0.0f, 0.0f)) * rotate4x4Y(0.7f),
                                             translate4x4(float3(-3.0f, 1.0f, 0.5f)) * scale4x4(float3(0.5f, 1.5f, 1.0f))};
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    Rays rays;
    for (int i = 0; i < 10000; ++i)
    {
      const float3 from(6.0f * u(rng), 6.0f * u(rng), 6.0f * u(rng)), to(4.0f * u(rng), u(rng), u(rng));
      rays.Add(from, to - from);
    }
    const Outcome o = TraceEverywhere(SceneOf("sah", mesh, instances), rays, 8.0f);
    std::set<uint32_t> instancesHit;
    for (const CRT_Hit& h : o.original)
      if (h.primId != kMiss)
        instancesHit.insert(h.instId);
    REQUIRE(instancesHit.size() == 3);
  }
  SECTION("NaN or inf in a ray, a zero direction and tmin == tmax miss")
  {
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    Rays rays;
    rays.Add(float3(nan, 0.0f, 2.0f), float3(0.0f, 0.0f, -1.0f));
    rays.Add(float3(0.0f, inf, 2.0f), float3(0.0f, 0.0f, -1.0f));
    rays.Add(float3(0.0f, 0.0f, 2.0f), float3(0.0f, nan, -1.0f));
    rays.Add(float3(0.0f, 0.0f, 2.0f), float3(-inf, 0.0f, -1.0f));
    rays.Add(float3(0.0f, 0.0f, 2.0f), float3(0.0f, 0.0f, 0.0f));
    rays.Add(float3(0.0f, 0.0f, 2.0f), float3(0.0f, 0.0f, -1.0f), 1.0f, 1.0f);  // tmin == tmax on the sphere
    rays.Add(float3(0.0f, 0.0f, 2.0f), float3(0.0f, 0.0f, -1.0f), nan, 10.0f);
    rays.Add(float3(0.0f, 0.0f, 2.0f), float3(0.0f, 0.0f, -1.0f), 0.0f, nan);
    const Outcome o = TraceEverywhere(SceneOf("lbvh", Sphere(3)), rays, 2.0f);
    REQUIRE(Misses(o.original) == rays.Size());
    if (o.hasVulkan)
      REQUIRE(Misses(o.vulkan) == rays.Size());
  }
}

TEST_CASE("PrimaryRays renders the same image as written, on _CPU, _ISPC and _Vulkan", "[composition][device-features]")
{
  const TriangleMesh mesh = BumpySphere(4);
  auto scene = SceneOf("lbvh", mesh);
  auto render = [&](PrimaryRays& r) {
    r.SetScene(scene, mesh.positions, mesh.indices);
    r.SetCamera(float3(0.5f, 0.8f, 3.0f), float3(0.0f), float3(0.0f, 1.0f, 0.0f), 45.0f);
    r.SetOcclusion(4, 0.5f);
    r.CommitDeviceData();
    std::vector<uint32_t> pixels(size_t(r.Width()) * r.Height());
    r.Render(pixels.data());
    return pixels;
  };
  PrimaryRays original(96, 64);
  const std::vector<uint32_t> expected = render(original);
  size_t background = 0;
  for (uint32_t p : expected)
    background += p == PackRGBA8(float3(0.6f, 0.65f, 0.7f));
  REQUIRE(background > 1000);                   // the sphere does not fill the frame...
  REQUIRE(background < expected.size() - 1000);  // ...but covers much of it
  REQUIRE(render(*CreatePrimaryRays_CPU(96, 64)) == expected);
#ifdef CROSSRT_HAS_ISPC
  REQUIRE(render(*CreatePrimaryRays_ISPC(96, 64)) == expected);
  // _ISPC runs Render's rows and columns in tiles (foreach_tiled), four rows a chunk: a size that is
  // no multiple of the tiles leaves partial tiles at the right and a partial chunk at the bottom.
  PrimaryRays odd(37, 23);
  REQUIRE(render(*CreatePrimaryRays_ISPC(37, 23)) == render(odd));
#endif
  auto ctx = ValidatedContext();
  if (!ctx)
    return;
  PrimaryRays_Vulkan vulkan(ctx, 96, 64);
  // Where the device has ray queries, the hardware traces by default; elsewhere asking for it throws.
  REQUIRE(vulkan.UsesRayTracingHardware() == ctx->hasRayQuery);
  if (!ctx->hasRayQuery)
    REQUIRE_THROWS_WITH(vulkan.UseRayTracingHardware(true), Catch::Contains("has no ray queries"));
  // The hardware where the device has ray queries (the hw variant), else the translated traversal
  // (the sw variant hides them): lavapipe 25 compiles the traversal some 6x slower than Mesa 22.
  {
    const bool hardware = ctx->hasRayQuery;
    vulkan.UseRayTracingHardware(hardware);
    const std::vector<uint32_t> gpu = render(vulkan);
    RequireNoValidationMessages(ctx);
    size_t differing = 0;
    for (size_t i = 0; i < gpu.size(); ++i)
      differing += gpu[i] != expected[i];
    // Only an occlusion ray grazing an edge may go the other way.
    INFO((hardware ? "ray tracing hardware: " : "translated traversal: ") << differing << " pixels differ");
    REQUIRE(differing <= gpu.size() / 200);
  }
}

TEST_CASE("BVHScene exports the committed scene that hardware acceleration structures are built from", "[composition][device-features]")
{
  // Two meshes, three instances, one of an empty mesh; the export rebuilt as a second BVHScene must
  // give the very same hits: primIds in the order added, instance ids and matrices kept.
  const TriangleMesh sphere = BumpySphere(3), box = Cube();
  auto scene = MakeSceneRT("lbvh");
  const uint32_t sphereId = scene->AddGeom_Triangles3f(sphere.positions.data(), sphere.positions.size() / 3, sphere.indices.data(), sphere.indices.size());
  const uint32_t emptyId = scene->AddGeom_Triangles3f(sphere.positions.data(), sphere.positions.size() / 3, nullptr, 0);
  const uint32_t boxId = scene->AddGeom_Triangles3f(box.positions.data(), box.positions.size() / 3, box.indices.data(), box.indices.size());
  scene->AddInstance(sphereId, translate4x4(float3(-1.5f, 0.0f, 0.0f)));
  scene->AddInstance(emptyId, float4x4());
  scene->AddInstance(boxId, translate4x4(float3(1.5f, 0.0f, 0.0f)) * rotate4x4Y(0.5f) * scale4x4(float3(1.0f, 2.0f, 1.0f)));

  CRT_SceneExport uncommitted;
  REQUIRE(scene->ExportScene(uncommitted));
  REQUIRE(uncommitted.instances.empty());  // queries miss before CommitScene: so must the hardware
  scene->CommitScene();
  CRT_SceneExport exported;
  REQUIRE(scene->ExportScene(exported));
  REQUIRE(exported.meshTriangles.size() == 3);
  REQUIRE(exported.meshTriangles[sphereId].size() == 9 * sphere.indices.size() / 3);
  REQUIRE(exported.meshTriangles[emptyId].empty());
  REQUIRE(exported.instances.size() == 3);
  REQUIRE(exported.instances[2].geomId == boxId);
  for (size_t t = 0; t < sphere.indices.size() / 3; t += 37)
    for (int corner = 0; corner < 3; ++corner)
      for (int axis = 0; axis < 3; ++axis)
        REQUIRE(exported.meshTriangles[sphereId][9 * t + 3 * corner + axis] == sphere.positions[3 * sphere.indices[3 * t + corner] + axis]);

  auto rebuilt = MakeSceneRT("lbvh");
  for (const auto& triangles : exported.meshTriangles)
  {
    std::vector<uint32_t> indices(triangles.size() / 3);
    for (uint32_t i = 0; i < indices.size(); ++i)
      indices[i] = i;
    rebuilt->AddGeom_Triangles3f(triangles.data(), triangles.size() / 3, indices.data(), indices.size());
  }
  for (const auto& inst : exported.instances)
  {
    float4x4 m;
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 4; ++col)
        m(row, col) = inst.toWorldRows[4 * row + col];
    rebuilt->AddInstance(inst.geomId, m);
  }
  rebuilt->CommitScene();
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  size_t hits = 0;
  for (int i = 0; i < 4000; ++i)
  {
    const float4 org(3.0f * u(rng), 3.0f * u(rng), 4.0f, 0.0f), dir(0.3f * u(rng), 0.3f * u(rng), -1.0f, 100.0f);
    const CRT_Hit a = scene->RayQuery_NearestHit(org, dir), b = rebuilt->RayQuery_NearestHit(org, dir);
    REQUIRE(std::memcmp(&a, &b, sizeof(CRT_Hit)) == 0);
    hits += a.primId != kMiss;
  }
  REQUIRE(hits > 400);  // both instances are hit often
}

TEST_CASE("Translated traversal: signed distance fields, from outside, from inside, along voxel faces, scaled, invalid rays",
          "[sdf][composition]")  // fields do not export: the translated traversal only
{
  // A rounded box at 32^3 voxels as a grid, an SVS and an SBS; the SDF leaves' code runs as written,
  // on _CPU (the same bits) and on _Vulkan. Voxel indices (primId) agree as triangles do above; t
  // within the same tolerance (the cubic's Newton steps see fma contractions like the edge
  // functions); normals, where the interpolant has a gradient, within 1e-3 of a unit dot.
  const litesdf::SdfRoundedBox shape(float3(0.0f), float3(0.55f, 0.45f, 0.5f), 0.1f);
  const float3 boxMin(-1.0f);
  const litesdf::SdfGrid grid = litesdf::BuildGrid(shape, boxMin, 2.0f, 33);
  const litesdf::SdfSVS svs = litesdf::BuildSVS(shape, boxMin, 2.0f, 5, 2);
  const litesdf::SdfSBS sbs = litesdf::BuildSBS(shape, boxMin, 2.0f, 5, 4, 1);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const float h = 2.0f / 32.0f;
  Rays rays;
  std::vector<bool> mustHit;
  for (int i = 0; i < 1500; ++i)  // from outside at the box
  {
    const float3 from = 3.0f * normalize(float3(u(rng), u(rng), u(rng)));
    rays.Add(from, 0.6f * float3(u(rng), u(rng), u(rng)) - from);
    mustHit.push_back(false);
  }
  for (int i = 0; i < 600; ++i)  // from inside: none may leak out; some on voxel faces, some along the axes
  {
    float3 p = 0.4f * float3(u(rng), u(rng), u(rng));
    if (i % 3 == 0)
      p = float3(std::round(p.x / h) * h, std::round(p.y / h) * h, p.z);
    float3 d = float3(u(rng), u(rng), u(rng));
    if (i % 2 == 0)
    {
      d = float3(0.0f);
      d[i % 6 / 2] = i % 4 == 0 ? 1.0f : -1.0f;
    }
    rays.Add(p, d);
    mustHit.push_back(true);
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  rays.Add(float3(0.0f, 0.0f, -3.0f), float3(nan, 0.0f, 1.0f));
  rays.Add(float3(0.0f, 0.0f, -3.0f), float3(0.0f, 0.0f, 0.0f));
  rays.Add(float3(0.0f, 0.0f, -3.0f), float3(0.0f, 0.0f, 1.0f), 2.3f, 2.3f);
  rays.Add(float3(0.0f, 0.0f, -3.0f), float3(0.0f, 0.0f, 1.0f), 0.0f, 2.3f);  // ends before the surface (at 2.4)
  for (int k = 0; k < 4; ++k)
    mustHit.push_back(false);
  const size_t firstInvalid = rays.Size() - 4;

  for (int kind = 0; kind < 3; ++kind)
    for (float scale : {1.0f, 1e-3f, 1e3f})
    {
      INFO((kind == 0 ? "grid" : kind == 1 ? "SVS" : "SBS") << " scaled by " << scale);
      auto scene = MakeSceneRT("sah");
      const uint32_t g = kind == 0 ? scene->AddGeom_SdfGrid(grid) : kind == 1 ? scene->AddGeom_SdfSVS(svs) : scene->AddGeom_SdfSBS(sbs);
      scene->AddInstance(g, scale4x4(float3(scale)));
      scene->CommitScene();
      Rays scaled;
      for (size_t i = 0; i < rays.Size(); ++i)
        scaled.Add(to_float3(rays.posAndNear[i]) * scale, to_float3(rays.dirAndFar[i]), rays.posAndNear[i].w * scale,
                   std::min(rays.dirAndFar[i].w * scale, 1e30f));
      const Outcome o = TraceEverywhere(scene, scaled, 2.0f * scale, nullptr, false);
      REQUIRE(Misses(o.original) < 1300);
      for (const auto* hits : {&o.original, &o.cpu, &o.vulkan})
        for (size_t i = 0; i < hits->size(); ++i)
        {
          INFO("ray " << i);
          if (mustHit[i])
            REQUIRE((*hits)[i].primId != kMiss);
          if (i >= firstInvalid)
            REQUIRE((*hits)[i].primId == kMiss);
        }
      if (o.hasVulkan)
        for (size_t i = 0; i < o.original.size(); ++i)
          if (o.original[i].primId != kMiss && o.vulkan[i].primId != kMiss)
          {
            const float3 a(o.original[i].coords[0], o.original[i].coords[1], o.original[i].coords[2]);
            const float3 b(o.vulkan[i].coords[0], o.vulkan[i].coords[1], o.vulkan[i].coords[2]);
            INFO("ray " << i);
            if (dot(a, a) == 0.0f || dot(b, b) == 0.0f)
              continue;  // a start inside, in a voxel of equal values: no gradient to compare
            REQUIRE(dot(a, b) > 0.999f);
          }
    }
}

TEST_CASE("A translated class whose composed member holds another implementation says which", "[composition]")
{
  // PrimaryRays_Vulkan runs BVHScene's traversal, composed in: an Embree scene cannot stand in for it.
  auto ctx = ValidatedContext();
  if (!ctx)
    return;
  auto vulkan = std::make_shared<PrimaryRays_Vulkan>(ctx, 1, 1);
  vulkan->SetScene(SceneOf("embree", Sphere(1)), {}, {});
  Rays rays;
  rays.Add(float3(0.0f, 0.0f, -3.0f), float3(0.0f, 0.0f, 1.0f));
  std::vector<CRT_Hit> hits(1);
  REQUIRE_THROWS_WITH(
      [&] {
        vulkan->CommitDeviceData();
        vulkan->CastRays(rays.posAndNear.data(), rays.dirAndFar.data(), hits.data(), 1);
      }(),
      Catch::Contains("must hold a BVHScene") && Catch::Contains("but it holds a ") && Catch::Contains("EmbreeRT"));
  RequireNoValidationMessages(ctx);
}

namespace {

// PrimaryRays_Vulkan as a user subclasses it: the specialization its pipelines were made with.
class InspectedPrimaryRays : public PrimaryRays_Vulkan
{
public:
  using PrimaryRays_Vulkan::PrimaryRays_Vulkan;
  std::vector<uint32_t> PipelineConstants() const { return crt_pipelineConstants; }
};

}  // namespace

TEST_CASE("Translated traversal specialised to the scene: a scene that gains transforms, fields and motion between frames",
          "[bvh][composition][specialize]")
{
  // One PrimaryRays_Vulkan over one BVHScene, whose kinds (m_sceneKinds, CRT_SPECIALIZE) grow frame
  // by frame: still triangles at the identity, then a transformed instance, a signed distance field,
  // a moving instance. Each frame's pipelines hold the scene's kinds, and the hits agree with
  // BVHScene as written: a shader still made for the earlier kinds would have no code for the new
  // geometry and would miss it.
  auto ctx = ValidatedContext();
  if (!ctx)
    return;
  auto scene = MakeSceneRT("sah");
  auto* bvh = dynamic_cast<BVHScene*>(scene.get());
  REQUIRE(bvh);
  const TriangleMesh mesh = Sphere(3);
  const uint32_t sphere = scene->AddGeom_Triangles3f(mesh.positions.data(), mesh.VertexCount(), mesh.indices.data(), mesh.indices.size());
  const litesdf::SdfRoundedBox box(float3(0.0f), float3(0.5f), 0.1f);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Rays rays;
  for (int i = 0; i < 3000; ++i)
  {
    const float3 from(0.0f, 0.5f, -12.0f), to(7.0f * u(rng), 2.0f * u(rng), 0.0f);
    rays.Add(from, to - from);
  }
  auto vulkan = std::make_shared<InspectedPrimaryRays>(ctx, 1, 1);
  vulkan->UseRayTracingHardware(false);
  vulkan->SetScene(scene, {}, {});
  const float4x4 steps[2] = {translate4x4(float3(-5.0f, 0.0f, 0.0f)), translate4x4(float3(-5.0f, 1.0f, 0.0f))};
  const struct
  {
    const char* added;
    uint32_t kinds;
  } frames[] = {
      {"a sphere at the identity", kSceneTriangles},
      {"a second sphere, moved and scaled", kSceneTriangles | kSceneTransformed},
      {"a signed distance field", kSceneTriangles | kSceneTransformed | kInstanceBoxes | kInstanceSdf},
      {"a moving sphere", kSceneTriangles | kSceneTransformed | kInstanceBoxes | kInstanceSdf | kInstanceMotion},
  };
  std::set<uint32_t> instancesHit;
  for (int f = 0; f < 4; ++f)
  {
    INFO("frame " << f << ": " << frames[f].added);
    if (f == 0) scene->AddInstance(sphere, float4x4());
    if (f == 1) scene->AddInstance(sphere, translate4x4(float3(2.5f, 0.0f, 0.0f)) * scale4x4(float3(0.7f)));
    if (f == 2) scene->AddInstance(scene->AddGeom_SdfGrid(litesdf::BuildGrid(box, float3(-1.0f), 2.0f, 17)), translate4x4(float3(5.0f, 0.0f, 0.0f)));
    if (f == 3) scene->AddInstanceMotion(sphere, steps, 2);
    scene->CommitScene();
    REQUIRE(bvh->m_sceneKinds == frames[f].kinds);
    std::vector<CRT_Hit> original, hits(rays.Size());
    for (size_t i = 0; i < rays.Size(); ++i)
      original.push_back(scene->RayQuery_NearestHit(rays.posAndNear[i], rays.dirAndFar[i]));
    vulkan->CastRays(rays.posAndNear.data(), rays.dirAndFar.data(), hits.data(), int(rays.Size()));  // commits by itself
    REQUIRE(vulkan->PipelineConstants() == std::vector<uint32_t>{frames[f].kinds});
    RequireNoValidationMessages(ctx);
    RequireAgreement("translated traversal", original, hits, rays, 12.0f, nullptr, RoundsLikeTheCpu(*ctx));
    for (const CRT_Hit& h : original)
      if (h.primId != kMiss)
        instancesHit.insert(h.instId);
    REQUIRE(instancesHit.size() == size_t(f + 1));  // each frame's new instance is in the rays' way
  }
}
