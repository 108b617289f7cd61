// Composition of a user's interface: SphereTracer holds an ISdf and its _Vulkan class runs
// SdfSpheres::Distance (composed with COMPOSE ISdf=SdfSpheres) on the GPU. The original, _CPU and
// _Vulkan must give the same depths, also after the implementation's plain members change.
#include "Composed.h"
#include "SphereTracer_CPU.h"
#include "SphereTracer_Vulkan.h"
#include "TestSupport.h"

#include <random>

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
  auto ctx = ValidatedContext();
  std::shared_ptr<SphereTracer> gpu = ctx ? CreateSphereTracer_Vulkan(ctx) : nullptr;
  for (SphereTracer* t : {&original, cpu.get(), gpu.get()})
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
