// Signed distance fields in the ray tracing stack: AddGeom_SdfGrid/SVS/SBS on Embree (user geometry
// calling litesdf's leaf tests) and on BVHScene (its own leaf code over packed values, the code the
// GPU runs when composed). Both must give litesdf's answers, mixed with triangle meshes and placed
// by instances, at the extremes: rays from inside that must not leak out, rays along voxel faces,
// NaN rays, tmin == tmax, scales 1e-3 to 1e3, and bad fields refused with a reason.
#include "CrossRT.h"
#include "SdfBVH.h"
#include "SdfTrace.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <string>

using namespace litesdf;
using LiteMath::float3;
using LiteMath::float4;
using LiteMath::float4x4;

namespace {

const char* const kScenes[] = {"embree", "sah", "lbvh"};

float3 RandomUnit(std::mt19937& rng)
{
  std::normal_distribution<float> n(0.0f, 1.0f);
  return LiteMath::normalize(float3(n(rng), n(rng), n(rng)));
}

CRT_Hit Nearest(ISceneObject& scene, float3 o, float3 d, float tmin = 0.0f, float tmax = 1e9f)
{
  return scene.RayQuery_NearestHit(float4(o.x, o.y, o.z, tmin), float4(d.x, d.y, d.z, tmax));
}

bool Hit(const CRT_Hit& h) { return h.instId != 0xFFFFFFFFu; }

// The three kinds of field of one shape over the cube [-1, 1]^3, 32 voxels per axis.
struct Fields
{
  SdfGrid grid;
  SdfSVS svs;
  SdfSBS sbs;
  BVHTree svsBvh, sbsBvh;
  explicit Fields(const ISdf& shape)
      : grid(BuildGrid(shape, float3(-1.0f), 2.0f, 33)), svs(BuildSVS(shape, float3(-1.0f), 2.0f, 5, 2)),
        sbs(BuildSBS(shape, float3(-1.0f), 2.0f, 5, 4, 1)), svsBvh(BuildSdfBVH(svs)), sbsBvh(BuildSdfBVH(sbs))
  {
  }
};

// A scene of one field, placed as it is; kind 0 grid, 1 SVS, 2 SBS.
std::shared_ptr<ISceneObject> SceneOf(const char* impl, const Fields& f, int kind)
{
  auto scene = MakeSceneRT(impl);
  const uint32_t g = kind == 0 ? scene->AddGeom_SdfGrid(f.grid) : kind == 1 ? scene->AddGeom_SdfSVS(f.svs) : scene->AddGeom_SdfSBS(f.sbs);
  scene->AddInstance(g, LiteMath::float4x4());
  scene->CommitScene();
  return scene;
}

// litesdf's answer for the same field (kSdfNewtonIterations: 4).
SdfHit Expected(const Fields& f, int kind, float3 o, float3 d, float tmin, float tmax)
{
  if (kind == 0)
    return IntersectGrid(f.grid, o, d, tmin, tmax, 4);
  return kind == 1 ? TraceSVS(f.svs, f.svsBvh, o, d, tmin, tmax, 4) : TraceSBS(f.sbs, f.sbsBvh, o, d, tmin, tmax, 4);
}

const char* KindName(int kind) { return kind == 0 ? "grid" : kind == 1 ? "SVS" : "SBS"; }

}  // namespace

TEST_CASE("SDF scenes: Embree and BVHScene give litesdf's hits and normals on every kind of field", "[sdf][litert]")
{
  const SdfTorus torus(float3(0.0f), 0.55f, 0.2f);
  const Fields fields(torus);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.8f, 0.8f);
  std::vector<float3> origins, dirs;
  for (int i = 0; i < 400; ++i)
  {
    origins.push_back(3.0f * RandomUnit(rng));
    dirs.push_back(LiteMath::normalize(float3(u(rng), u(rng), u(rng)) - origins.back()));
  }
  for (int kind = 0; kind < 3; ++kind)
    for (const char* impl : kScenes)
    {
      auto scene = SceneOf(impl, fields, kind);
      int hits = 0, disagree = 0;
      float maxDt = 0.0f, minDot = 1.0f;
      for (size_t i = 0; i < origins.size(); ++i)
      {
        const SdfHit want = Expected(fields, kind, origins[i], dirs[i], 0.0f, 1e9f);
        const CRT_Hit got = Nearest(*scene, origins[i], dirs[i]);
        if ((want.t >= 0.0f) != Hit(got))
        {
          ++disagree;
          continue;
        }
        if (!Hit(got))
          continue;
        ++hits;
        CHECK(got.geomId == 0u);
        CHECK(got.instId == 0u);
        maxDt = std::max(maxDt, std::fabs(got.t - want.t));
        minDot = std::min(minDot, LiteMath::dot(want.normal, float3(got.coords[0], got.coords[1], got.coords[2])));
      }
      INFO(impl << " on the " << KindName(kind) << ": " << hits << " hits, " << disagree << " disagree, max |dt| " << maxDt
                << ", min normal dot " << minDot);
      CHECK(hits > 150);
      CHECK(disagree == 0);
      CHECK(maxDt < 1e-4f);
      CHECK(minDot > 0.9999f);
    }
}

TEST_CASE("SDF scenes: rays from inside never leak out, axis-aligned ones along voxel faces included", "[sdf][litert]")
{
  const SdfRoundedBox box(float3(0.0f), float3(0.55f, 0.45f, 0.5f), 0.1f);
  const Fields fields(box);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.4f, 0.4f);
  const float h = 2.0f / 32.0f;  // the voxel edge
  for (int kind = 0; kind < 3; ++kind)
    for (const char* impl : kScenes)
    {
      auto scene = SceneOf(impl, fields, kind);
      int rays = 0, leaks = 0;
      for (int i = 0; i < 300; ++i)
      {
        // A point inside, snapped onto voxel faces for a third of the rays, and a direction that is
        // random or along an axis.
        float3 p(u(rng), u(rng), u(rng));
        if (i % 3 == 0)
          p = float3(std::round(p.x / h) * h, std::round(p.y / h) * h, p.z);
        float3 d = RandomUnit(rng);
        if (i % 2 == 0)
        {
          const int axis = i % 6 / 2;
          d = float3(0.0f);
          d[axis] = (i % 4 == 0) ? 1.0f : -1.0f;
        }
        ++rays;
        leaks += !Hit(Nearest(*scene, p, d));
      }
      INFO(impl << " on the " << KindName(kind) << ": " << rays << " rays from inside, " << leaks << " leaked");
      CHECK(leaks == 0);
    }
}

TEST_CASE("SDF scenes: fields and meshes mixed under instances, the nearest of them reported", "[sdf][litert]")
{
  const SdfSphere sphere(float3(0.0f), 0.7f);
  const Fields fields(sphere);
  // A quad at z = 0 (two triangles), and the sphere's SVS and SBS placed at z = -2 and z = +2.
  const float quad[] = {-5.0f, -5.0f, 0.0f, 5.0f, -5.0f, 0.0f, 5.0f, 5.0f, 0.0f, -5.0f, 5.0f, 0.0f};
  const uint32_t quadIndices[] = {0, 1, 2, 0, 2, 3};
  for (const char* impl : kScenes)
  {
    auto scene = MakeSceneRT(impl);
    const uint32_t mesh = scene->AddGeom_Triangles3f(quad, 4, quadIndices, 6);
    const uint32_t svs = scene->AddGeom_SdfSVS(fields.svs);
    const uint32_t sbs = scene->AddGeom_SdfSBS(fields.sbs);
    CHECK(svs == 1u);
    CHECK(sbs == 2u);
    scene->AddInstance(mesh, float4x4());
    scene->AddInstance(svs, LiteMath::translate4x4(float3(0.0f, 0.0f, -2.0f)));
    scene->AddInstance(sbs, LiteMath::translate4x4(float3(0.0f, 0.0f, 2.0f)) * LiteMath::scale4x4(float3(2.0f)));
    scene->CommitScene();
    INFO(impl);
    // Down the z axis from -10: the SVS sphere first, at z = -2.7.
    const CRT_Hit a = Nearest(*scene, float3(0.0f, 0.0f, -10.0f), float3(0.0f, 0.0f, 1.0f));
    CHECK(a.instId == 1u);
    CHECK(a.geomId == svs);
    CHECK(a.t == Approx(7.3f).margin(2e-3));
    CHECK(a.coords[2] == Approx(-1.0f).margin(0.01));  // the normal, object space (of the interpolant)
    // Up from z = -1: the quad; from z = 0.5: the scaled SBS sphere (radius 1.4) at z = 0.6.
    const CRT_Hit b = Nearest(*scene, float3(0.1f, 0.1f, -1.0f), float3(0.0f, 0.0f, 1.0f));
    CHECK(b.instId == 0u);
    CHECK(b.t == Approx(1.0f));
    const CRT_Hit c = Nearest(*scene, float3(0.0f, 0.0f, 0.5f), float3(0.0f, 0.0f, 1.0f));
    CHECK(c.instId == 2u);
    CHECK(c.geomId == sbs);
    CHECK(c.t == Approx(0.1f).margin(4e-3));
    // Shadow rays: blocked by the field, not by what lies beyond tmax.
    CHECK(scene->RayQuery_AnyHit(float4(0.0f, 0.0f, -10.0f, 0.0f), float4(0.0f, 0.0f, 1.0f, 7.4f)));
    CHECK_FALSE(scene->RayQuery_AnyHit(float4(0.0f, 0.0f, -10.0f, 0.0f), float4(0.0f, 0.0f, 1.0f, 7.2f)));
  }
}

TEST_CASE("SDF scenes: NaN and inf rays, tmin == tmax, scales from 1e-3 to 1e3, bad fields", "[sdf][litert]")
{
  const SdfSphere sphere(float3(0.0f), 0.7f);
  const Fields fields(sphere);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (const char* impl : kScenes)
  {
    INFO(impl);
    for (int kind = 0; kind < 3; ++kind)
    {
      auto scene = SceneOf(impl, fields, kind);
      const float3 o(0.0f, 0.0f, -2.0f), d(0.0f, 0.0f, 1.0f);
      CHECK(Nearest(*scene, o, d).t == Approx(1.3f).margin(2e-3));
      for (float3 bad : {float3(nan, 0.0f, 1.0f), float3(inf, 0.0f, 1.0f), float3(0.0f)})
        CHECK_FALSE(Hit(Nearest(*scene, o, bad)));
      CHECK_FALSE(Hit(Nearest(*scene, float3(nan, 0.0f, -2.0f), d)));
      CHECK_FALSE(Hit(Nearest(*scene, o, d, 1.29f, 1.29f)));  // an empty interval just before the surface
      CHECK_FALSE(Hit(Nearest(*scene, o, d, 0.0f, 1.25f)));   // tmax inside the voxel before the surface
      CHECK(Nearest(*scene, o, d, 1.28f, 10.0f).t == Approx(1.3f).margin(2e-3));  // tmin inside it
    }
    // The same field placed at 1e-3 and 1e3: the hit scales with it.
    for (float scale : {1e-3f, 1e3f})
    {
      auto scene = MakeSceneRT(impl);
      scene->AddInstance(scene->AddGeom_SdfSVS(fields.svs), LiteMath::scale4x4(float3(scale)));
      scene->CommitScene();
      const CRT_Hit hit = Nearest(*scene, float3(0.0f, 0.0f, -2.0f * scale), float3(0.0f, 0.0f, 1.0f));
      CHECK(hit.t / scale == Approx(1.3f).margin(2e-3));
    }
    auto scene = MakeSceneRT(impl);
    SdfSVS broken = fields.svs;
    broken.values.pop_back();
    CHECK_THROWS_WITH(scene->AddGeom_SdfSVS(broken), Catch::Contains("words of values for"));
    SdfSBS deep = fields.sbs;
    deep.depth = 11;
    CHECK_THROWS_WITH(scene->AddGeom_SdfSBS(deep), Catch::Contains("depth must be at most 10"));
    SdfGrid empty;
    CHECK_THROWS_AS(scene->AddGeom_SdfGrid(empty), std::invalid_argument);
    // A voxel one past the cube's last, and a brick sticking out of it by one voxel.
    REQUIRE(!fields.svs.coords.empty());
    REQUIRE(!fields.sbs.coords.empty());
    REQUIRE(fields.svs.depth < 10);
    SdfSVS outside = fields.svs;
    outside.coords[0] = 1u << fields.svs.depth;
    CHECK_THROWS_WITH(scene->AddGeom_SdfSVS(outside), Catch::Contains("is outside the cube"));
    SdfSBS sticking = fields.sbs;
    sticking.coords[0] = ((1u << fields.sbs.depth) - fields.sbs.brickSize + 1) << 10;
    CHECK_THROWS_WITH(scene->AddGeom_SdfSBS(sticking), Catch::Contains("is outside the cube"));
  }
}
