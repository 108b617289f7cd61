// Composition of a user's interface: SphereTracer holds an ISdf and its _Vulkan class runs
// SdfSpheres::Distance (composed with COMPOSE ISdf=SdfSpheres) on the GPU, and its _ISPC class in
// SIMD lanes. The original, _CPU, _ISPC and _Vulkan must give the same depths, also after the
// implementation's plain members change.
#include "Composed.h"
#include "ShapeTracer.h"
#include "ShapeTracer_CPU.h"
#include "ShapeTracer_Vulkan.h"
#include "SphereTracer_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "ShapeTracer_ISPC.h"
#include "SphereTracer_ISPC.h"
#endif
#include "SphereTracer_Vulkan.h"
#include "TestSupport.h"

#include <random>

using LiteMath::float3;
using LiteMath::float4;

TEST_CASE("Composition of a user's interface: plain and vector members of the implementation reach the GPU", "[equivalence][composition]")
{
  auto shape = std::make_shared<SdfSpheres>();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 12; ++i)
    shape->m_spheres.push_back(float4(2.0f * u(rng), 2.0f * u(rng), u(rng), 0.3f + 0.2f * std::fabs(u(rng))));
  shape->m_count = 12;
  const int n = 4099;
  std::vector<float4> origins(n);
  for (auto& o : origins)
    o = float4(2.5f * u(rng), 2.5f * u(rng), 5.0f, 0.0f);

  SphereTracer original;
  auto cpu = CreateSphereTracer_CPU();
#ifdef CROSSRT_HAS_ISPC
  std::shared_ptr<SphereTracer> lanes = CreateSphereTracer_ISPC();
#else
  std::shared_ptr<SphereTracer> lanes;
#endif
  auto ctx = ValidatedContext();
  std::shared_ptr<SphereTracer> gpu = ctx ? CreateSphereTracer_Vulkan(ctx) : nullptr;
  for (SphereTracer* t : {&original, cpu.get(), lanes.get(), gpu.get()})
    if (t)
    {
      t->SetShape(shape);
      t->CommitDeviceData();
    }
  // Sharp union, then blended, then fewer spheres: each a change of a plain member only.
  std::vector<float> previous;
  for (auto [smoothing, count] : {std::pair<float, int>{0.0f, 12}, {0.4f, 12}, {0.4f, 5}})
  {
    INFO("smoothing " << smoothing << ", " << count << " spheres");
    shape->m_smoothing = smoothing;
    shape->m_count = count;
    std::vector<float> expected(n), onCpu(n), onGpu(n);
    original.Trace(n, origins.data(), expected.data());
    size_t hits = 0;
    for (float d : expected)
      hits += d >= 0.0f;
    REQUIRE(hits > n / 20);
    REQUIRE(hits < n);
    REQUIRE(expected != previous);  // the change matters
    previous = expected;
    cpu->Trace(n, origins.data(), onCpu.data());
    REQUIRE(onCpu == expected);
    if (lanes)
    {
      std::vector<float> onLanes(n);
      lanes->Trace(n, origins.data(), onLanes.data());
      REQUIRE(onLanes == expected);  // no fused multiply-adds, C++'s min and max: the same floats
    }
    if (!gpu)
      continue;
    gpu->Trace(n, origins.data(), onGpu.data());
    RequireNoValidationMessages(ctx);
    // A march that ends within 1e-4 of the surface on one side may need one more step on the
    // other: depths agree to 1e-3, and hit/miss agrees but for rays that graze a sphere.
    size_t differ = 0;
    for (int i = 0; i < n; ++i)
      differ += (expected[i] < 0.0f) != (onGpu[i] < 0.0f) || std::fabs(expected[i] - onGpu[i]) > 1e-3f;
    REQUIRE(differ <= size_t(n) / 1000);
  }
}

// Listing 2 of the paper: the composed traversal (ShapeScene::Trace) calls a virtual Intersect per
// leaf it reaches; on the GPU that call is a switch over the shape's class, whose data (16, 32 and
// 48 bytes) sits in a buffer per class.
TEST_CASE("Composition: virtual intersection functions called from the composed traversal", "[equivalence][composition][virtual][device-features]")
{
  auto scene = std::make_shared<ShapeScene>();
  scene->Add(std::make_shared<Sphere>(float3(0.0f, 0.0f, 0.0f), 0.75f));
  scene->Add(std::make_shared<Box>(float3(1.0f, -1.5f, -0.5f), float3(2.0f, -0.5f, 0.5f)));
  scene->Add(std::make_shared<Disc>(float3(-1.5f, 1.2f, 0.0f), LiteMath::normalize(float3(0.3f, 0.0f, 1.0f)), 0.6f));
  scene->Add(std::make_shared<Sphere>(float3(1.4f, 1.3f, -0.3f), 0.5f));
  scene->Add(std::make_shared<Box>(float3(-2.2f, -2.0f, -1.0f), float3(-0.8f, -0.9f, 0.2f)));
  scene->Add(std::make_shared<Disc>(float3(0.2f, -0.2f, 1.0f), float3(0.0f, 0.0f, 1.0f), 0.3f));  // in front of the first sphere
  // Lights, a second vector of leaves: one half behind the first sphere.
  scene->AddLight(std::make_shared<Sphere>(float3(-0.3f, 1.9f, 0.5f), 0.35f));
  scene->AddLight(std::make_shared<Disc>(float3(1.9f, 0.6f, 1.5f), float3(0.0f, 0.0f, 1.0f), 0.4f));
  scene->AddLight(std::make_shared<Box>(float3(-1.0f, -0.4f, -3.0f), float3(-0.2f, 0.4f, -2.5f)));
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const int n = 3001;
  std::vector<float4> origins(n), dirs(n);
  for (int i = 0; i < n; ++i)
  {
    origins[i] = float4(2.5f * u(rng), 2.5f * u(rng), 5.0f, 0.0f);
    const float3 d = LiteMath::normalize(float3(0.1f * u(rng), 0.1f * u(rng), -1.0f));
    dirs[i] = float4(d.x, d.y, d.z, 0.0f);
  }
  const float far = 100.0f;
  ShapeTracer original;
  original.SetScene(scene);
  std::vector<ShapeHit> expected(n);
  original.Trace(n, origins.data(), dirs.data(), far, expected.data());
  // The original itself: a ray straight down the z axis onto the disc in front of the first sphere,
  // at distance 5 - 1; and every class of shape is hit somewhere, and some rays miss.
  {
    const float4 o(0.2f, -0.2f, 5.0f, 0.0f), d(0.0f, 0.0f, -1.0f, 0.0f);
    ShapeHit h;
    original.Trace(1, &o, &d, far, &h);
    REQUIRE(h.shape == 5u);
    REQUIRE(std::fabs(h.t - 4.0f) < 1e-5f);
    REQUIRE(h.nz == 1.0f);
  }
  std::vector<int> perShape(6, 0), perLight(3, 0);
  int misses = 0;
  for (auto& h : expected)
    if (h.shape == ~0u) ++misses;
    else if (h.shape >= ShapeScene::kLightHit) ++perLight.at(h.shape - ShapeScene::kLightHit);
    else ++perShape.at(h.shape);
  for (int s = 0; s < 6; ++s) REQUIRE(perShape[s] > 10);
  for (int s = 0; s < 3; ++s) REQUIRE(perLight[s] > 10);
  REQUIRE(misses > n / 4);

  auto ctx = ValidatedContext();
  auto cpu = CreateShapeTracer_CPU();
  std::shared_ptr<ShapeTracer_Vulkan> gpu = ctx ? std::make_shared<ShapeTracer_Vulkan>(ctx) : nullptr;
  // Level 3: the leaves are intersection shaders of a ray tracing pipeline where the device has
  // them (the default there), the switch of level 2 elsewhere.
  if (gpu)
  {
    REQUIRE(gpu->UsesRayTracingPipelines() == ctx->hasRayTracingPipeline);
    if (!ctx->hasRayTracingPipeline)
    {
      INFO(ctx->DeviceName() << " has no ray tracing pipelines: the intersection shaders are only compiled and validated (spirv.hardware_variants)");
      REQUIRE_THROWS_WITH(gpu->UseRayTracingPipelines(true), Catch::Contains("has no ray tracing pipelines"));
      REQUIRE_FALSE(gpu->UsesRayTracingPipelines());
    }
  }
  struct Run
  {
    const char* name;
    ShapeTracer* tracer;
    bool intersectionShaders;
  };
  std::vector<Run> runs = {{"CPU", cpu.get(), false}};
#ifdef CROSSRT_HAS_ISPC
  auto lanes = CreateShapeTracer_ISPC();  // level 3 on the CPU: the switch, lane by lane
  runs.push_back({"ISPC", lanes.get(), false});
#endif
  if (gpu && ctx->hasRayTracingPipeline) runs.push_back({"Vulkan, intersection shaders", gpu.get(), true});
  if (gpu) runs.push_back({"Vulkan, switch", gpu.get(), false});
  for (const Run& run : runs)
  {
    INFO(run.name);
    if (run.tracer == gpu.get()) gpu->UseRayTracingPipelines(run.intersectionShaders);
    run.tracer->SetScene(scene);
    std::vector<ShapeHit> hits(n);
    run.tracer->Trace(n, origins.data(), dirs.data(), far, hits.data());
    int sameShape = 0;
    for (int i = 0; i < n; ++i)
    {
      if (hits[i].shape != expected[i].shape) continue;  // a grazing ray may tip over an edge
      ++sameShape;
      INFO("ray " << i);
      if (hits[i].shape == ~0u)
        REQUIRE(hits[i].t == far);
      else
      {
        REQUIRE(std::fabs(hits[i].t - expected[i].t) <= 1e-4f * expected[i].t);
        REQUIRE(std::fabs(hits[i].nx - expected[i].nx) + std::fabs(hits[i].ny - expected[i].ny) + std::fabs(hits[i].nz - expected[i].nz) <= 1e-3f);
      }
    }
    REQUIRE(sameShape >= n - n / 200);
  }
  // A shape moved: CommitDeviceData() copies the objects (and builds the leaves' boxes) again.
  for (const Run& run : runs)
  {
    if (run.tracer != gpu.get()) continue;
    INFO(run.name);
    gpu->UseRayTracingPipelines(run.intersectionShaders);
    auto moved = std::make_shared<Sphere>(float3(0.2f, -0.2f, 2.0f), 0.5f);
    const auto first = scene->m_shapes[0];
    scene->m_shapes[0] = moved;
    scene->m_boxes[0] = moved->BoxMin();
    scene->m_boxes[1] = moved->BoxMax();
    gpu->CommitDeviceData();
    const float4 o(0.2f, -0.2f, 5.0f, 0.0f), d(0.0f, 0.0f, -1.0f, 0.0f);
    ShapeHit h;
    gpu->Trace(1, &o, &d, far, &h);
    REQUIRE(h.shape == 0u);
    REQUIRE(std::fabs(h.t - 2.5f) < 1e-5f);
    // A light moved in front of it: the second vector's leaves are committed too.
    auto movedLight = std::make_shared<Sphere>(float3(0.2f, -0.2f, 3.5f), 0.25f);
    const auto firstLight = scene->m_lights[0];
    scene->m_lights[0] = movedLight;
    scene->m_lightBoxes[0] = movedLight->BoxMin();
    scene->m_lightBoxes[1] = movedLight->BoxMax();
    gpu->CommitDeviceData();
    gpu->Trace(1, &o, &d, far, &h);
    REQUIRE(h.shape == ShapeScene::kLightHit + 0u);
    REQUIRE(std::fabs(h.t - 1.25f) < 1e-5f);
    scene->m_shapes[0] = first;  // back, for the next run
    scene->m_boxes[0] = first->BoxMin();
    scene->m_boxes[1] = first->BoxMax();
    scene->m_lights[0] = firstLight;
    scene->m_lightBoxes[0] = firstLight->BoxMin();
    scene->m_lightBoxes[1] = firstLight->BoxMax();
    gpu->CommitDeviceData();
  }
  RequireNoValidationMessages(ctx);
}
