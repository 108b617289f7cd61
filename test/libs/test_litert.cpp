// Tests for the CrossRT ray query interface, run on every implementation: Embree, and CrossRT's
// own BVH traversal over LBVH and binned SAH trees.
#include <catch2/catch.hpp>

#include "CrossRT.h"

#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

using namespace LiteMath;

namespace
{
constexpr uint32_t MISS = 0xFFFFFFFFu;

// Unit quad in the z=0 plane: triangle 0 = (v0,v1,v2) covers y < x, triangle 1 = (v0,v2,v3) covers y > x.
const float    QUAD_VERTS[]   = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
const uint32_t QUAD_INDICES[] = {0, 1, 2, 0, 2, 3};

float4 down(float tmax = 100.0f) { return float4(0, 0, -1, tmax); }
float4 from(float x, float y, float z, float tmin = 0.0f) { return float4(x, y, z, tmin); }

// Every implementation CreateSceneRT knows; each test runs once per name.
const char* anyImplementation() { return GENERATE(as<const char*>{}, "embree", "lbvh", "sah"); }

std::shared_ptr<ISceneObject> makeQuadScene(const char* name)
{
  auto scene = MakeSceneRT(name);
  const uint32_t g = scene->AddGeom_Triangles3f(QUAD_VERTS, 4, QUAD_INDICES, 6);
  REQUIRE(g == 0);
  REQUIRE(scene->AddInstance(g, float4x4()) == 0);
  scene->CommitScene();
  return scene;
}
} // namespace

TEST_CASE("CrossRT factory", "[litert]")
{
  for (const char* name : {"embree", "lbvh", "sah"})
  {
    auto scene = MakeSceneRT(name);
    REQUIRE(scene != nullptr);
    CHECK(std::string(scene->Name()) == name);
  }
  CHECK(std::string(MakeSceneRT("LBVH")->Name()) == "lbvh");  // names are case-insensitive
  CHECK_THROWS_AS(MakeSceneRT("nope"), std::invalid_argument);
  CHECK_THROWS_WITH(MakeSceneRT("nope"), Catch::Contains("nope") && Catch::Contains("embree") && Catch::Contains("lbvh") &&
                                               Catch::Contains("sah"));
}

TEST_CASE("CrossRT nearest hit on a quad", "[litert]")
{
  const char* impl = anyImplementation();
  INFO(impl);
  auto scene = makeQuadScene(impl);

  // (0.75, 0.25) lies in triangle 0: p = u*v1 + v*v2 = (u+v, v) -> v = 0.25, u = 0.5.
  const CRT_Hit h0 = scene->RayQuery_NearestHit(from(0.75f, 0.25f, 1.0f), down());
  CHECK(h0.primId == 0);
  CHECK(h0.instId == 0);
  CHECK(h0.geomId == 0);
  CHECK(h0.t == Approx(1.0f));
  CHECK(h0.coords[0] == Approx(0.5f));
  CHECK(h0.coords[1] == Approx(0.25f));
  CHECK(h0.coords[2] == 0.0f);
  CHECK(h0.coords[3] == 0.0f);

  // (0.25, 0.75) lies in triangle 1 = (v0, v2, v3): p = u*(1,1) + v*(0,1) -> u = 0.25, v = 0.5.
  const CRT_Hit h1 = scene->RayQuery_NearestHit(from(0.25f, 0.75f, 3.0f), down());
  CHECK(h1.primId == 1);
  CHECK(h1.t == Approx(3.0f));
  CHECK(h1.coords[0] == Approx(0.25f));
  CHECK(h1.coords[1] == Approx(0.5f));

  // Unnormalized direction: t is in units of the direction length.
  const CRT_Hit h2 = scene->RayQuery_NearestHit(from(0.5f, 0.2f, 4.0f), float4(0, 0, -2, 100));
  CHECK(h2.t == Approx(2.0f));

  // Beside the quad: miss.
  const CRT_Hit miss = scene->RayQuery_NearestHit(from(1.5f, 0.5f, 1.0f), down());
  CHECK(miss.primId == MISS);
  CHECK(miss.instId == MISS);
  CHECK(miss.geomId == MISS);

  // Pointing away, and a segment that ends before the quad, and one that starts after it.
  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.2f, 1.0f), float4(0, 0, 1, 100)).primId == MISS);
  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.2f, 1.0f), down(0.5f)).primId == MISS);
  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.2f, 1.0f, 1.5f), down()).primId == MISS);
  // tmin == tmax, even exactly at the hit distance: empty interval, miss.
  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.2f, 1.0f, 1.0f), down(1.0f)).primId == MISS);
  // Unbounded ray.
  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.2f, 1.0f), down(INF_POSITIVE)).primId == 0);
}

TEST_CASE("CrossRT any hit", "[litert]")
{
  const char* impl = anyImplementation();
  INFO(impl);
  auto scene = makeQuadScene(impl);
  CHECK(scene->RayQuery_AnyHit(from(0.5f, 0.2f, 1.0f), down()));
  CHECK(scene->RayQuery_AnyHit(from(0.5f, 0.2f, -1.0f), float4(0, 0, 1, 100))); // hits the back side too
  CHECK_FALSE(scene->RayQuery_AnyHit(from(2.0f, 2.0f, 1.0f), down()));
  CHECK_FALSE(scene->RayQuery_AnyHit(from(0.5f, 0.2f, 1.0f), down(0.99f)));
  CHECK(scene->RayQuery_AnyHit(from(0.5f, 0.2f, 1.0f), down(1.01f)));
  CHECK_FALSE(scene->RayQuery_AnyHit(from(0.5f, 0.2f, 1.0f, 2.0f), down(2.0f)));
}

TEST_CASE("CrossRT invalid rays miss without crashing", "[litert]")
{
  const char* impl = anyImplementation();
  INFO(impl);
  auto        scene = makeQuadScene(impl);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const float4 rays[][2] = {
      {from(nan, 0.5f, 1.0f), down()},
      {from(0.5f, 0.2f, 1.0f), float4(nan, nan, nan, 100)},
      {from(0.5f, 0.2f, 1.0f), float4(0, 0, -1, nan)},
      {from(0.5f, 0.2f, 1.0f, nan), down()},
      {from(inf, 0.2f, 1.0f), down()},
      {from(0.5f, 0.2f, 1.0f), float4(0, -inf, -1, 100)},
      {from(0.5f, 0.2f, 1.0f), float4(0, 0, 0, 100)}, // zero direction
      {from(0.5f, 0.2f, 1.0f, 5.0f), down(1.0f)},     // tmin > tmax
  };
  for (const auto& r : rays)
  {
    CHECK(scene->RayQuery_NearestHit(r[0], r[1]).primId == MISS);
    CHECK_FALSE(scene->RayQuery_AnyHit(r[0], r[1]));
  }
}

TEST_CASE("CrossRT instances", "[litert]")
{
  const char* impl = anyImplementation();
  INFO(impl);
  auto           scene = MakeSceneRT(impl);
  const uint32_t quad  = scene->AddGeom_Triangles3f(QUAD_VERTS, 4, QUAD_INDICES, 6, BUILD_MEDIUM);

  // Second mesh: one triangle with a 4-float vertex stride (the 4th float is padding).
  const float    strided[] = {0, 0, 0, 99, 1, 0, 0, 99, 0, 1, 0, 99};
  const uint32_t triIdx[]  = {0, 1, 2};
  const uint32_t tri = scene->AddGeom_Triangles3f(strided, 3, triIdx, 3, BUILD_LOW, 4 * sizeof(float));
  CHECK(quad == 0);
  CHECK(tri == 1);

  const uint32_t i0 = scene->AddInstance(quad, float4x4());
  const uint32_t i1 = scene->AddInstance(quad, translate4x4(float3(10, 0, 0)));
  const uint32_t i2 = scene->AddInstance(tri, translate4x4(float3(0, 5, -2)) * scale4x4(float3(2, 2, 2)));
  const uint32_t i3 = scene->AddInstance(quad, translate4x4(float3(20, 0, 0)) * rotate4x4X(0.5f * M_PI_F));
  CHECK((i0 == 0 && i1 == 1 && i2 == 2 && i3 == 3));
  scene->CommitScene(BUILD_HIGH);

  // Translated copy of the quad.
  CRT_Hit h = scene->RayQuery_NearestHit(from(10.75f, 0.25f, 1.0f), down());
  CHECK(h.instId == 1);
  CHECK(h.geomId == 0);
  CHECK(h.primId == 0);
  CHECK(h.t == Approx(1.0f));
  CHECK(h.coords[0] == Approx(0.5f));
  CHECK(scene->RayQuery_NearestHit(from(0.75f, 0.25f, 1.0f), down()).instId == 0);
  CHECK(scene->RayQuery_NearestHit(from(5.0f, 0.25f, 1.0f), down()).primId == MISS);

  // Scaled strided triangle: covers x + y < 2 around (0,5) at z = -2. A padding value leaking
  // into the positions (stride bug) would move it.
  h = scene->RayQuery_NearestHit(from(0.5f, 5.5f, 0.0f), down());
  CHECK(h.instId == 2);
  CHECK(h.geomId == 1);
  CHECK(h.primId == 0);
  CHECK(h.t == Approx(2.0f));
  CHECK(scene->RayQuery_NearestHit(from(1.2f, 6.2f, 0.0f), down()).primId == MISS); // x+y = 2.4 in object space

  // Quad rotated +90 degrees about X: y -> z, so it spans z in [0,1] in the plane y = 0.
  h = scene->RayQuery_NearestHit(from(20.5f, 3.0f, 0.8f), float4(0, -1, 0, 100));
  CHECK(h.instId == 3);
  CHECK(h.t == Approx(3.0f));
  CHECK(scene->RayQuery_NearestHit(from(20.5f, 3.0f, -0.2f), float4(0, -1, 0, 100)).primId == MISS);

  // The nearest of two overlapping instances along a ray wins.
  const uint32_t i4 = scene->AddInstance(quad, translate4x4(float3(10, 0, -1)));
  scene->CommitScene();
  h = scene->RayQuery_NearestHit(from(10.5f, 0.2f, -3.0f), float4(0, 0, 1, 100));
  CHECK(h.instId == i4);
  CHECK(h.t == Approx(2.0f));

  // Moving an instance.
  scene->UpdateInstance(i1, translate4x4(float3(30, 0, 0)));
  scene->CommitScene();
  CHECK(scene->RayQuery_NearestHit(from(10.75f, 0.25f, 1.0f), down()).instId == i4);
  h = scene->RayQuery_NearestHit(from(30.75f, 0.25f, 1.0f), down());
  CHECK(h.instId == i1);
  CHECK(h.t == Approx(1.0f));

  // Clearing the scene removes instances but keeps meshes.
  scene->ClearScene();
  scene->CommitScene();
  CHECK(scene->RayQuery_NearestHit(from(0.75f, 0.25f, 1.0f), down()).primId == MISS);
  CHECK(scene->AddInstance(tri, float4x4()) == 0);
  scene->CommitScene();
  h = scene->RayQuery_NearestHit(from(0.2f, 0.2f, 1.0f), down());
  CHECK(h.geomId == tri);
  CHECK(h.instId == 0);

  CHECK_THROWS_AS(scene->AddInstance(7, float4x4()), std::out_of_range);
  CHECK_THROWS_AS(scene->UpdateInstance(9, float4x4()), std::out_of_range);
}

TEST_CASE("CrossRT geometry update and validation", "[litert]")
{
  const char* impl = anyImplementation();
  INFO(impl);
  auto scene = makeQuadScene(impl);

  // Same sizes: in-place update (move the quad to z = -1).
  float moved[12];
  for (int i = 0; i < 12; i++)
    moved[i] = QUAD_VERTS[i] - (i % 3 == 2 ? 1.0f : 0.0f);
  scene->UpdateGeom_Triangles3f(0, moved, 4, QUAD_INDICES, 6, BUILD_REFIT);
  scene->CommitScene(BUILD_REFIT);
  CRT_Hit h = scene->RayQuery_NearestHit(from(0.75f, 0.25f, 1.0f), down());
  CHECK(h.primId == 0);
  CHECK(h.t == Approx(2.0f));

  // Different size: a single bigger triangle replaces the quad.
  const float    big[]   = {0, 0, 0, 4, 0, 0, 0, 4, 0};
  const uint32_t bigIdx[] = {0, 1, 2};
  scene->UpdateGeom_Triangles3f(0, big, 3, bigIdx, 3);
  scene->CommitScene();
  h = scene->RayQuery_NearestHit(from(2.5f, 0.5f, 1.0f), down());
  CHECK(h.primId == 0);
  CHECK(h.t == Approx(1.0f));

  const uint32_t badIdx[] = {0, 1, 5};
  CHECK_THROWS_AS(scene->AddGeom_Triangles3f(big, 3, badIdx, 3), std::invalid_argument);
  CHECK_THROWS_AS(scene->AddGeom_Triangles3f(big, 3, bigIdx, 2), std::invalid_argument);
  CHECK_THROWS_AS(scene->UpdateGeom_Triangles3f(5, big, 3, bigIdx, 3), std::out_of_range);

  // An empty mesh is allowed and never hit.
  const uint32_t empty = scene->AddGeom_Triangles3f(nullptr, 0, nullptr, 0);
  scene->AddInstance(empty, translate4x4(float3(0, 0, 5)));
  scene->CommitScene();
  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.5f, 1.0f), down()).t == Approx(1.0f));

  // ClearGeom drops everything.
  scene->ClearGeom();
  scene->CommitScene();
  CHECK_FALSE(scene->RayQuery_AnyHit(from(0.5f, 0.5f, 1.0f), down()));
  CHECK(scene->AddGeom_Triangles3f(QUAD_VERTS, 4, QUAD_INDICES, 6) == 0);
}

TEST_CASE("CrossRT refuses non-finite vertices and singular or non-finite instance matrices", "[litert]")
{
  const char* impl = anyImplementation();
  INFO(impl);
  auto scene = makeQuadScene(impl);
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (float bad : {inf, -inf, nan})
  {
    float verts[12];
    for (int i = 0; i < 12; i++)
      verts[i] = QUAD_VERTS[i];
    verts[7] = bad;  // vertex 2's y
    try
    {
      scene->AddGeom_Triangles3f(verts, 4, QUAD_INDICES, 6);
      FAIL("a vertex at " << bad << " was accepted");
    }
    catch (const std::invalid_argument& e)
    {
      CHECK(std::string(e.what()).find("vertex 2") != std::string::npos);
      CHECK(std::string(e.what()).find("not finite") != std::string::npos);
    }
    CHECK_THROWS_AS(scene->UpdateGeom_Triangles3f(0, verts, 4, QUAD_INDICES, 6), std::invalid_argument);
  }
  // A non-finite vertex no triangle uses changes nothing: accepted.
  float unused[15];
  for (int i = 0; i < 12; i++)
    unused[i] = QUAD_VERTS[i];
  unused[12] = unused[13] = unused[14] = nan;
  CHECK_NOTHROW(scene->AddGeom_Triangles3f(unused, 5, QUAD_INDICES, 6));

  float4x4 singular = float4x4();
  singular(2, 2) = 0.0f;  // flattens z
  float4x4 notFinite = translate4x4(float3(0, nan, 0));
  for (const float4x4& m : {singular, notFinite})
  {
    CHECK_THROWS_AS(scene->AddInstance(0, m), std::invalid_argument);
    CHECK_THROWS_AS(scene->UpdateInstance(0, m), std::invalid_argument);
    const float4x4 motion[2] = {float4x4(), m};
    CHECK_THROWS_AS(scene->AddInstanceMotion(0, motion, 2), std::invalid_argument);
  }
  // The scene is as it was: the first quad still hit, nothing crashed.
  scene->CommitScene();
  const CRT_Hit h = scene->RayQuery_NearestHit(from(0.75f, 0.25f, 1.0f), down());
  CHECK(h.primId == 0);
  CHECK(h.instId == 0);
}

TEST_CASE("CrossRT queries before commit miss", "[litert]")
{
  const char* impl = anyImplementation();
  INFO(impl);
  auto scene = MakeSceneRT(impl);
  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.2f, 1.0f), down()).primId == MISS);
  scene->AddInstance(scene->AddGeom_Triangles3f(QUAD_VERTS, 4, QUAD_INDICES, 6), float4x4());
  CHECK_FALSE(scene->RayQuery_AnyHit(from(0.5f, 0.2f, 1.0f), down()));
  scene->CommitScene();
  CHECK(scene->RayQuery_AnyHit(from(0.5f, 0.2f, 1.0f), down()));
}

TEST_CASE("CrossRT concurrent queries", "[litert]")
{
  const char* impl = anyImplementation();
  INFO(impl);
  auto scene = MakeSceneRT(impl);
  const uint32_t g = scene->AddGeom_Triangles3f(QUAD_VERTS, 4, QUAD_INDICES, 6);
  for (int i = 0; i < 16; i++)
    scene->AddInstance(g, translate4x4(float3(2.0f * float(i), 0, -float(i))));
  scene->CommitScene();

  // Each thread shoots rays at every instance; the expected answer follows from the layout.
  std::atomic<int>         errors{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; t++)
    threads.emplace_back([&, t]() {
      for (int iter = 0; iter < 2000; iter++)
      {
        const int     i   = (iter + t) % 16;
        const bool    low = (iter % 2) == 0; // alternate between the two triangles
        const float   x   = 2.0f * float(i) + (low ? 0.75f : 0.25f);
        const float   y   = low ? 0.25f : 0.75f;
        const CRT_Hit h   = scene->RayQuery_NearestHit(from(x, y, 1.0f), down());
        if (h.instId != uint32_t(i) || h.primId != (low ? 0u : 1u) || std::abs(h.t - (1.0f + float(i))) > 1e-4f)
          errors++;
        if (!scene->RayQuery_AnyHit(from(x, y, 1.0f), down()) || scene->RayQuery_AnyHit(from(x + 1.0f, y, 1.0f), down()))
          errors++;
      }
    });
  for (auto& th : threads)
    th.join();
  CHECK(errors.load() == 0);
}

namespace
{
CRT_AABB box(float x0, float y0, float z0, float x1, float y1, float z1)
{
  return CRT_AABB{float4(x0, y0, z0, 0.0f), float4(x1, y1, z1, 0.0f)};
}
} // namespace

TEST_CASE("CrossRT box geometry: a ray hits a box where it enters it", "[litert]")
{
  const char* impl = anyImplementation();
  INFO(impl);
  auto scene = MakeSceneRT(impl);

  // A quad at z = 0 and, above it, two unit boxes at z in [1, 2]: x in [0, 1] and in [2, 3].
  const uint32_t quad = scene->AddGeom_Triangles3f(QUAD_VERTS, 4, QUAD_INDICES, 6);
  const CRT_AABB boxes[] = {box(0, 0, 1, 1, 1, 2), box(2, 0, 1, 3, 1, 2)};
  const uint32_t boxGeom = scene->AddGeom_AABB(7, boxes, 2);
  REQUIRE((boxGeom & CRT_GEOM_MASK_AABB_BIT) != 0);
  REQUIRE((boxGeom & CRT_GEOM_MASK_AABB_BIT_RM) == 1);  // the second geometry
  REQUIRE(scene->AddInstance(quad, float4x4()) == 0);
  REQUIRE(scene->AddInstance(boxGeom, float4x4()) == 1);
  scene->CommitScene();

  // Straight down onto the first box: it enters at z = 2, before the quad.
  const CRT_Hit a = scene->RayQuery_NearestHit(from(0.5f, 0.5f, 5.0f), down());
  CHECK(a.t == Approx(3.0f));
  CHECK(a.geomId == boxGeom);
  CHECK(a.instId == 1);
  CHECK(a.primId == 0);
  CHECK(a.coords[0] == 0.0f);

  // The second box is the second primitive.
  const CRT_Hit b = scene->RayQuery_NearestHit(from(2.5f, 0.5f, 5.0f), down());
  CHECK(b.t == Approx(3.0f));
  CHECK(b.primId == 1);
  CHECK(b.geomId == boxGeom);

  // Sideways through both boxes: the nearer one, entered through its x = 0 face.
  const CRT_Hit c = scene->RayQuery_NearestHit(from(-1.0f, 0.5f, 1.5f), float4(1, 0, 0, 100));
  CHECK(c.t == Approx(1.0f));
  CHECK(c.primId == 0);
  // Backwards from past the second box: the second box first.
  const CRT_Hit d = scene->RayQuery_NearestHit(from(4.0f, 0.5f, 1.5f), float4(-1, 0, 0, 100));
  CHECK(d.t == Approx(1.0f));
  CHECK(d.primId == 1);

  // From inside a box the hit is at tmin.
  const CRT_Hit e = scene->RayQuery_NearestHit(from(0.5f, 0.5f, 1.5f, 0.25f), down());
  CHECK(e.t == Approx(0.25f));
  CHECK(e.geomId == boxGeom);

  // Between the boxes the quad's x range ends at 1, so the ray misses everything.
  const CRT_Hit f = scene->RayQuery_NearestHit(from(1.5f, 0.5f, 5.0f), down());
  CHECK(f.primId == MISS);
  CHECK(f.geomId == MISS);
  CHECK_FALSE(scene->RayQuery_AnyHit(from(1.5f, 0.5f, 5.0f), down()));
  CHECK(scene->RayQuery_AnyHit(from(2.5f, 0.5f, 5.0f), down()));

  // A ray that stops before the box misses it; one that stops inside hits.
  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.5f, 5.0f), down(2.5f)).primId == MISS);
  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.5f, 5.0f), down(3.5f)).geomId == boxGeom);
}

TEST_CASE("CrossRT box geometry: primitives of several boxes, instances and updates", "[litert]")
{
  const char* impl = anyImplementation();
  INFO(impl);
  auto scene = MakeSceneRT(impl);

  // Four boxes in a row along x, two per custom primitive: boxes 0-1 are primitive 0, 2-3 primitive 1.
  const CRT_AABB boxes[] = {box(0, 0, 0, 1, 1, 1), box(1, 0, 0, 2, 1, 1), box(2, 0, 0, 3, 1, 1), box(3, 0, 0, 4, 1, 1)};
  int prims[2] = {0, 1};
  void* primPtrs[2] = {&prims[0], &prims[1]};
  const uint32_t g = scene->AddGeom_AABB(3, boxes, 4, primPtrs, 2);
  REQUIRE(scene->AddInstance(g, float4x4()) == 0);
  REQUIRE(scene->AddInstance(g, translate4x4(float3(0, 0, -10))) == 1);
  scene->CommitScene();

  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.5f, 5.0f), down()).primId == 0);
  CHECK(scene->RayQuery_NearestHit(from(1.5f, 0.5f, 5.0f), down()).primId == 0);
  CHECK(scene->RayQuery_NearestHit(from(2.5f, 0.5f, 5.0f), down()).primId == 1);
  CHECK(scene->RayQuery_NearestHit(from(3.5f, 0.5f, 5.0f), down()).primId == 1);

  // The moved instance: below the first, reached from underneath.
  const CRT_Hit below = scene->RayQuery_NearestHit(from(3.5f, 0.5f, -20.0f), float4(0, 0, 1, 100));
  CHECK(below.instId == 1);
  CHECK(below.t == Approx(10.0f));
  CHECK(below.primId == 1);

  // Updating the boxes (same count): the row moves up by 10.
  const CRT_AABB moved[] = {box(0, 0, 10, 1, 1, 11), box(1, 0, 10, 2, 1, 11), box(2, 0, 10, 3, 1, 11), box(3, 0, 10, 4, 1, 11)};
  scene->UpdateGeom_AABB(g, 3, moved, 4, primPtrs, 2);
  scene->CommitScene();
  const CRT_Hit up = scene->RayQuery_NearestHit(from(0.5f, 0.5f, 20.0f), down());
  CHECK(up.t == Approx(9.0f));
  CHECK(up.instId == 0);
  // The old place is empty; the moved instance's copy now sits at z in [0, 1].
  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.5f, 5.0f), down(3.5f)).primId == MISS);
  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.5f, 5.0f), down()).instId == 1);
}

namespace
{
// A user's scene written against LiteRT's newer ISceneObject, whose box functions take build flags
// (kernel_slicer's tests 035-038 and 046 override these): it keeps the boxes and their flags.
struct FlaggedBoxes : public ISceneObject
{
  const char* Name() const override { return "FlaggedBoxes"; }
  void ClearGeom() override { boxes.clear(); }
  uint32_t AddGeom_Triangles3f(const float*, size_t, const uint32_t*, size_t, uint32_t = BUILD_HIGH, size_t = 3 * sizeof(float)) override { return 0; }
  void UpdateGeom_Triangles3f(uint32_t, const float*, size_t, const uint32_t*, size_t, uint32_t = BUILD_HIGH, size_t = 3 * sizeof(float)) override {}
  uint32_t AddGeom_AABB(uint32_t, const CRT_AABB* boxMinMaxF8, size_t boxNumber, uint32_t buildFlags, void**, size_t) override
  {
    boxes.assign(boxMinMaxF8, boxMinMaxF8 + boxNumber);
    flags = buildFlags;
    return CRT_GEOM_MASK_AABB_BIT;
  }
  void UpdateGeom_AABB(uint32_t, uint32_t, const CRT_AABB* boxMinMaxF8, size_t boxNumber, uint32_t buildFlags, void**, size_t) override
  {
    boxes.assign(boxMinMaxF8, boxMinMaxF8 + boxNumber);
    flags = buildFlags;
  }
  void ClearScene() override {}
  uint32_t AddInstance(uint32_t, const float4x4&) override { return 0; }
  void UpdateInstance(uint32_t, const float4x4&) override {}
  void CommitScene(uint32_t = BUILD_HIGH) override {}
  CRT_Hit RayQuery_NearestHit(float4, float4) override { return CRT_Hit{}; }
  bool RayQuery_AnyHit(float4, float4) override { return false; }
  std::vector<CRT_AABB> boxes;
  uint32_t flags = 0;
};
}  // namespace

TEST_CASE("CrossRT box geometry with build flags (LiteRT's newer form) and without", "[litert]")
{
  // Every implementation takes both forms: the same boxes, the same hits.
  const char* impl = anyImplementation();
  INFO(impl);
  const CRT_AABB boxes[] = {box(0, 0, 0, 1, 1, 1), box(2, 0, 0, 3, 1, 1)};
  auto scene = MakeSceneRT(impl);
  const uint32_t g = scene->AddGeom_AABB(5, boxes, 2, uint32_t(BUILD_LOW), nullptr, 0);
  REQUIRE((g & CRT_GEOM_MASK_AABB_BIT) != 0u);
  scene->AddInstance(g, float4x4());
  scene->CommitScene();
  CHECK(scene->RayQuery_NearestHit(from(2.5f, 0.5f, 5.0f), down()).primId == 1);
  const CRT_AABB moved[] = {box(0, 0, 0, 1, 1, 1), box(2, 0, 3, 3, 1, 4)};
  scene->UpdateGeom_AABB(g, 5, moved, 2, uint32_t(BUILD_LOW), nullptr, 0);
  scene->CommitScene();
  CHECK(scene->RayQuery_NearestHit(from(2.5f, 0.5f, 5.0f), down()).t == Approx(1.0f));

  // A scene that implements only the form with flags gets the older form's calls, with BUILD_HIGH.
  FlaggedBoxes flagged;
  ISceneObject& asInterface = flagged;
  CHECK(asInterface.AddGeom_AABB(5, boxes, 2) == CRT_GEOM_MASK_AABB_BIT);
  CHECK(flagged.boxes.size() == 2);
  CHECK(flagged.flags == uint32_t(BUILD_HIGH));
  asInterface.UpdateGeom_AABB(CRT_GEOM_MASK_AABB_BIT, 5, moved, 1);
  CHECK(flagged.boxes.size() == 1);
  CHECK(flagged.boxes[0].boxMax.x == 1.0f);
}

TEST_CASE("CrossRT motion instances interpolate their matrices over the ray's time", "[litert]")
{
  const char* impl = anyImplementation();
  INFO(impl);
  auto scene = MakeSceneRT(impl);

  const uint32_t quad = scene->AddGeom_Triangles3f(QUAD_VERTS, 4, QUAD_INDICES, 6);
  // Three steps at times 0, 0.5, 1: the quad slides 2 along x, then drops 1 along z.
  const float4x4 steps[] = {float4x4(), translate4x4(float3(2, 0, 0)), translate4x4(float3(2, 0, -1))};
  REQUIRE(scene->AddInstanceMotion(quad, steps, 3) == 0);
  scene->CommitScene(BUILD_HIGH | MOTION_BLUR);

  // At time 0 the quad covers x in [0, 1].
  CHECK(scene->RayQuery_NearestHitMotion(from(0.5f, 0.25f, 1.0f), down(), 0.0f).t == Approx(1.0f));
  CHECK(scene->RayQuery_NearestHitMotion(from(2.5f, 0.25f, 1.0f), down(), 0.0f).primId == MISS);
  // At time 0.25 it has slid by 1: x in [1, 2]; the hit's barycentrics are in the quad's own frame.
  const CRT_Hit mid = scene->RayQuery_NearestHitMotion(from(1.75f, 0.25f, 1.0f), down(), 0.25f);
  CHECK(mid.t == Approx(1.0f));
  CHECK(mid.primId == 0);
  CHECK(mid.instId == 0);
  CHECK(mid.coords[0] == Approx(0.5f));
  CHECK(mid.coords[1] == Approx(0.25f));
  CHECK(scene->RayQuery_NearestHitMotion(from(0.5f, 0.25f, 1.0f), down(), 0.25f).primId == MISS);
  // At time 0.75 it is halfway down: z = -0.5.
  CHECK(scene->RayQuery_NearestHitMotion(from(2.5f, 0.25f, 1.0f), down(), 0.75f).t == Approx(1.5f));
  // At time 1 it is at z = -1; times past 1 clamp to it.
  CHECK(scene->RayQuery_NearestHitMotion(from(2.5f, 0.25f, 1.0f), down(), 1.0f).t == Approx(2.0f));
  CHECK(scene->RayQuery_NearestHitMotion(from(2.5f, 0.25f, 1.0f), down(), 3.0f).t == Approx(2.0f));
  // Any hit follows the same motion.
  CHECK(scene->RayQuery_AnyHitMotion(from(1.75f, 0.25f, 1.0f), down(), 0.25f));
  CHECK_FALSE(scene->RayQuery_AnyHitMotion(from(1.75f, 0.25f, 1.0f), down(), 0.9f));
  // Queries without a time see time 0.
  CHECK(scene->RayQuery_NearestHit(from(0.5f, 0.25f, 1.0f), down()).t == Approx(1.0f));
}

TEST_CASE("CrossRT paper-style ownership: CreateSceneRT and DeleteSceneRT", "[litert]")
{
  std::shared_ptr<ISceneObject> scene(CreateSceneRT("sah"), DeleteSceneRT);
  REQUIRE(scene != nullptr);
  CHECK(std::string(scene->Name()) == "sah");
  CHECK_THROWS_AS(CreateSceneRT("nope"), std::invalid_argument);
}
