// litert's SdfLeafScene, the paper's level-3 form over signed distance fields, as a scene of its own:
// it must find what BVHScene finds for the same fields and instances (both solve litesdf's cubic per
// voxel, through different trees and brick walks), keep rays from inside in, miss the rays
// ISceneObject says miss, and refuse what it does not hold with a reason.
#include "CrossRT.h"
#include "SdfLeafScene.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>

using LiteMath::float3;
using LiteMath::float4;
using LiteMath::float4x4;

namespace
{
float3 RandomUnit(std::mt19937& rng)
{
  std::normal_distribution<float> n(0.0f, 1.0f);
  return LiteMath::normalize(float3(n(rng), n(rng), n(rng)));
}

// A torus as each kind of field (float values: both scenes then read the same numbers), each
// placed twice, once turned and scaled.
template <class Scene>
void Fill(Scene& scene)
{
  const litesdf::SdfTorus torus(float3(0.0f, 0.0f, 0.0f), 0.6f, 0.25f);
  const float3 corner(-1.0f, -1.0f, -1.0f);
  const uint32_t fields[3] = {scene.AddGeom_SdfGrid(litesdf::BuildGrid(torus, corner, 2.0f, 33)),
                              scene.AddGeom_SdfSVS(litesdf::BuildSVS(torus, corner, 2.0f, 5, 4)),
                              scene.AddGeom_SdfSBS(litesdf::BuildSBS(torus, corner, 2.0f, 5, 4, 4))};
  for (int k = 0; k < 3; ++k)
  {
    scene.AddInstance(fields[k], LiteMath::translate4x4(float3(2.5f * float(k - 1), 0.0f, 0.0f)));
    scene.AddInstance(fields[k], LiteMath::translate4x4(float3(2.5f * float(k - 1), 2.5f, 0.0f)) * LiteMath::rotate4x4X(0.7f) *
                                     LiteMath::scale4x4(float3(0.8f, 0.8f, 0.8f)));
  }
  scene.CommitScene();
}
}  // namespace

TEST_CASE("SdfLeafScene finds what BVHScene finds for the same fields and instances", "[sdf][litert]")
{
  SdfLeafScene leaves;
  Fill(leaves);
  auto bvh = MakeSceneRT("sah");
  Fill(*bvh);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  int hits = 0, agree = 0;
  const int n = 4000;
  int perInstance[6] = {0, 0, 0, 0, 0, 0};
  for (int i = 0; i < n; ++i)
  {
    const float3 o(4.0f * u(rng), 1.25f + 2.0f * u(rng), 4.0f);
    const float3 d = LiteMath::normalize(float3(0.2f * u(rng), 0.2f * u(rng), -1.0f));
    const float4 pos(o.x, o.y, o.z, 0.0f), dir(d.x, d.y, d.z, 100.0f);
    const CRT_Hit a = leaves.RayQuery_NearestHit(pos, dir), b = bvh->RayQuery_NearestHit(pos, dir);
    REQUIRE(leaves.RayQuery_AnyHit(pos, dir) == (a.instId != 0xFFFFFFFFu));
    if (a.instId != b.instId)
      continue;  // a ray grazing a field may tip over its edge in one walk and not the other
    ++agree;
    if (a.instId == 0xFFFFFFFFu)
      continue;
    ++hits;
    ++perInstance[a.instId];
    INFO("ray " << i);
    REQUIRE(a.geomId == b.geomId);
    REQUIRE(std::fabs(a.t - b.t) <= 1e-4f * b.t);
    REQUIRE(std::fabs(a.coords[0] - b.coords[0]) + std::fabs(a.coords[1] - b.coords[1]) + std::fabs(a.coords[2] - b.coords[2]) <= 1e-3f);
  }
  REQUIRE(agree >= n - n / 200);
  REQUIRE(hits > n / 8);
  for (int k = 0; k < 6; ++k)
    REQUIRE(perInstance[k] > n / 100);
}

TEST_CASE("SdfLeafScene keeps rays from inside in, misses what ISceneObject says misses, refuses what it lacks", "[sdf][litert]")
{
  SdfLeafScene scene;
  // Before a commit, every ray misses.
  REQUIRE(scene.RayQuery_NearestHit(float4(0, 0, 5, 0), float4(0, 0, -1, 100)).instId == 0xFFFFFFFFu);
  Fill(scene);
  // From random points inside the tube of the first torus (centre (-2.5, 0, 0)), every direction hits it.
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 500; ++i)
  {
    const float angle = 6.2831853f * u(rng), r = 0.15f * u(rng);
    const float3 onRing = float3(-2.5f + 0.6f * std::cos(angle), 0.0f, 0.6f * std::sin(angle));
    const float3 o = onRing + r * RandomUnit(rng), d = RandomUnit(rng);
    const CRT_Hit h = scene.RayQuery_NearestHit(float4(o.x, o.y, o.z, 0.0f), float4(d.x, d.y, d.z, 100.0f));
    INFO("ray " << i);
    REQUIRE(h.instId == 0u);
    REQUIRE(h.t <= 0.3f);  // within the tube's radius of where it started
  }
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const float4 toTorus(-2.5f, 0.0f, 5.0f, 0.0f), down(0.0f, 0.0f, -1.0f, 100.0f);
  REQUIRE(scene.RayQuery_NearestHit(float4(-2.5f + 0.6f, 0.0f, 5.0f, 0.0f), down).instId == 0u);
  for (const auto& [pos, dir] : {std::pair<float4, float4>{float4(nan, 0, 5, 0), down},
                                 {toTorus, float4(0, inf, -1, 100)},
                                 {toTorus, float4(0, 0, 0, 100)},
                                 {float4(-1.9f, 0.0f, 5.0f, 7.0f), float4(0.0f, 0.0f, -1.0f, 7.0f)}})
  {
    INFO(pos.x << " " << pos.y << " " << pos.z << " " << pos.w << " / " << dir.x << " " << dir.y << " " << dir.z << " " << dir.w);
    REQUIRE(scene.RayQuery_NearestHit(pos, dir).instId == 0xFFFFFFFFu);
    REQUIRE_FALSE(scene.RayQuery_AnyHit(pos, dir));
  }
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const uint32_t tri[3] = {0, 1, 2};
  REQUIRE_THROWS_WITH(scene.AddGeom_Triangles3f(v, 3, tri, 3), Catch::Contains("signed distance fields only"));
  REQUIRE_THROWS_WITH(scene.AddInstance(7, float4x4()), Catch::Contains("no field 7"));
  litesdf::SdfGrid odd = litesdf::BuildGrid(litesdf::SdfSphere(float3(0.0f, 0.0f, 0.0f), 0.5f), float3(-1.0f, -1.0f, -1.0f), 2.0f, 10);
  REQUIRE_THROWS_WITH(scene.AddGeom_SdfGrid(odd), Catch::Contains("not a multiple of 4"));
}
