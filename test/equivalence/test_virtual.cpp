// Virtual functions in kernels: MaterialShading, FlatShading and CallableShading call IMaterial
// through a std::vector of shared_ptr. The original, _CPU, _ISPC and _Vulkan shade the same points,
// at all three levels (the ISPC classes, at levels 1 and 2, keep each class's objects in an array
// of their own and switch over the class lane by lane): MaterialShading_Vulkan keeps each class's objects in a buffer of their own
// (level 2), FlatShading_Vulkan every element in one array of equal slots (level 1); a switch over
// the object's class picks the code. CallableShading_Vulkan (level 3) runs a callable shader per
// class where the device has ray tracing pipelines, the level-2 switch elsewhere. The GPU may
// contract a*b+c to fma, and pow differs by an ulp or so, hence 1e-5.
#include "CallableShading.h"
#include "CallableShading_CPU.h"
#include "CallableShading_Vulkan.h"
#include "FlatShading.h"
#include "FlatShading_CPU.h"
#include "FlatShading_Vulkan.h"
#include "MaterialShading.h"
#include "MaterialShading_CPU.h"
#include "MaterialShading_Vulkan.h"
#ifdef CROSSRT_HAS_ISPC
#include "CallableShading_ISPC.h"
#include "FlatShading_ISPC.h"
#include "MaterialShading_ISPC.h"
#endif
#include "TestSupport.h"

#include <functional>
#include <random>

namespace
{
// An implementation the translator never saw (it is defined here, not where MaterialShading is).
struct Glass : IMaterial
{
  float3 Shade(float3, float3) const override { return float3(0.0f); }
};

std::vector<std::shared_ptr<IMaterial>> Palette()
{
  auto lambert = [](float r, float g, float b) {
    auto m = std::make_shared<Lambert>();
    m->albedo = float3(r, g, b);
    return m;
  };
  auto phong = [](float shininess, float3 specular) {
    auto m = std::make_shared<Phong>();
    m->shininess = shininess;
    m->specular = specular;
    return m;
  };
  auto checker = [](int axis, float scale, float opacity) {
    auto m = std::make_shared<Checker>();
    m->axis = axis;
    m->scale = scale;
    m->opacity = opacity;
    return m;
  };
  // Classes interleaved, so that an element's index differs from its index among its class.
  return {lambert(0.9f, 0.1f, 0.1f), phong(8.0f, float3(0.3f)), checker(0, 4.0f, 0.25f), lambert(0.1f, 0.8f, 0.2f),
          phong(64.0f, float3(0.9f, 0.8f, 0.7f)), checker(2, 7.0f, 0.75f), phong(2.0f, float3(0.1f))};
}

struct Scene
{
  std::vector<float4> normals;
  std::vector<uint32_t> ids;
};

Scene RandomScene(int n, uint32_t materials, unsigned seed)
{
  std::mt19937 rng(seed);
  std::normal_distribution<float> g;
  Scene s;
  for (int i = 0; i < n; ++i)
  {
    const float3 v = LiteMath::normalize(float3(g(rng), g(rng), g(rng)));
    s.normals.push_back(float4(v.x, v.y, v.z, 0.0f));
    s.ids.push_back(uint32_t(rng() % materials));
  }
  return s;
}

template <typename Shading>
std::vector<float4> ShadeWith(Shading& shading, const Scene& s)
{
  std::vector<float4> colors(s.normals.size(), float4(-1.0f));
  shading.Shade(int(s.normals.size()), s.normals.data(), s.ids.data(), colors.data());
  return colors;
}

size_t Differing(const std::vector<float4>& a, const std::vector<float4>& b, float tolerance)
{
  size_t bad = 0;
  for (size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 4; ++c)
      if (!Close(a[i][c], b[i][c], tolerance))
      {
        ++bad;
        break;
      }
  return bad;
}
}  // namespace

// The translations of the same kernel, against the original of their class: _CPU, _ISPC (where ISPC
// is found) and _Vulkan (where a device is).
template <typename Shading>
void CheckVirtualCalls(std::shared_ptr<Shading> cpu, std::shared_ptr<Shading> ispc, std::function<std::shared_ptr<Shading>()> createGpu)
{
  auto ctx = ValidatedContext();
  const auto palette = Palette();
  const Scene scene = RandomScene(20011, uint32_t(palette.size()), 3);

  Shading original;
  original.m_materials = palette;
  const auto expected = ShadeWith(original, scene);
  // Every element was shaded, and both opacities (1 from the interface, the checkers' own) occur.
  size_t opaque = 0, translucent = 0;
  for (auto& c : expected) (c.w == 1.0f ? opaque : translucent) += 1;
  REQUIRE(opaque > expected.size() / 2);
  REQUIRE(translucent > expected.size() / 10);
  for (auto& c : expected) REQUIRE((c.w == 1.0f || c.w == 0.25f || c.w == 0.75f));

  cpu->m_materials = palette;
  REQUIRE(Differing(ShadeWith(*cpu, scene), expected, 0.0f) == 0);  // the same compiled C++ on all cores

  // The ISPC kernels' pow and the GPU's may differ from std::pow by an ulp or so.
  std::vector<std::pair<const char*, std::shared_ptr<Shading>>> translated;
  if (ispc) translated.push_back({"ISPC", ispc});
  if (ctx) translated.push_back({"Vulkan", createGpu()});
  for (auto& [name, t] : translated)
  {
    INFO(name);
    t->m_materials = palette;
    REQUIRE(Differing(ShadeWith(*t, scene), expected, 1e-5f) == 0);
  }

  SECTION("objects changed in place are seen after CommitDeviceData()")
  {
    auto changed = Palette();
    static_cast<Lambert&>(*changed[0]).albedo = float3(0.0f, 0.0f, 1.0f);
    static_cast<Checker&>(*changed[5]).opacity = 0.125f;
    changed[1] = changed[3];  // an element now holds another class: the tags change
    original.m_materials = changed;
    const auto expectedChanged = ShadeWith(original, scene);
    REQUIRE(Differing(expectedChanged, expected, 0.0f) > 0);
    for (auto& [name, t] : translated)
    {
      INFO(name);
      t->m_materials = changed;
      t->CommitDeviceData();
      REQUIRE(Differing(ShadeWith(*t, scene), expectedChanged, 1e-5f) == 0);
    }
  }
  SECTION("added objects are seen without CommitDeviceData()")
  {
    auto more = Palette();
    for (auto& m : Palette()) more.push_back(m);
    auto extra = std::make_shared<Checker>();
    extra->axis = 1;
    more.push_back(extra);
    const Scene wide = RandomScene(3001, uint32_t(more.size()), 4);
    original.m_materials = more;
    for (auto& [name, t] : translated)
    {
      INFO(name);
      t->m_materials = more;
      REQUIRE(Differing(ShadeWith(*t, wide), ShadeWith(original, wide), 1e-5f) == 0);
    }
  }
  SECTION("an element without an object, or of a class the translator never saw, is a clear error")
  {
    // The GPU class copies the objects in CommitDeviceData, the ISPC class before each kernel.
    for (auto& [name, t] : translated)
    {
      INFO(name);
      auto commitAndShade = [&, t = t] {
        t->CommitDeviceData();
        ShadeWith(*t, scene);
      };
      t->m_materials[2] = nullptr;
      REQUIRE_THROWS_WITH(commitAndShade(), Catch::Contains("m_materials[2] holds no object"));
      t->m_materials[2] = std::make_shared<Glass>();
      REQUIRE_THROWS_WITH(commitAndShade(), Catch::Contains("m_materials[2] holds a") && Catch::Contains("Glass") &&
                                                Catch::Contains("know") && Catch::Contains("Lambert, Phong, Checker"));
    }
  }
  RequireNoValidationMessages(ctx);
}

#ifdef CROSSRT_HAS_ISPC
#define CROSSRT_ISPC_OR_NULL(x) x
#else
#define CROSSRT_ISPC_OR_NULL(x) nullptr
#endif

TEST_CASE("Virtual functions, level 2: three implementations of different sizes, each in a buffer of its own", "[equivalence][virtual]")
{
  CheckVirtualCalls<MaterialShading>(CreateMaterialShading_CPU(), CROSSRT_ISPC_OR_NULL(CreateMaterialShading_ISPC()),
                                     [] { return CreateMaterialShading_Vulkan(ValidatedContext()); });
}

TEST_CASE("Virtual functions, level 1: the same kernel with every element in one array of equal slots", "[equivalence][virtual]")
{
  CheckVirtualCalls<FlatShading>(CreateFlatShading_CPU(), CROSSRT_ISPC_OR_NULL(CreateFlatShading_ISPC()),
                                 [] { return CreateFlatShading_Vulkan(ValidatedContext()); });
}

TEST_CASE("Virtual functions, level 3: callable shaders on ray tracing pipelines, else the level-2 switch", "[equivalence][virtual][device-features]")
{
  auto ctx = ValidatedContext();
  const auto palette = Palette();
  const int width = 61, height = 47;  // not multiples of a workgroup's side
  const Scene scene = RandomScene(width * height, uint32_t(palette.size()), 5);
  auto render = [&](CallableShading& shading) {
    std::vector<float4> colors(scene.normals.size(), float4(-1.0f));
    shading.Render(width, height, scene.normals.data(), scene.ids.data(), colors.data());
    return colors;
  };

  CallableShading original;
  original.m_materials = palette;
  const auto expected = render(original);
  // Attenuate (through a reference) dims what MaterialShading's kernel shades, more with x + y; the
  // opacity stays.
  MaterialShading plain;
  plain.m_materials = palette;
  const auto unattenuated = ShadeWith(plain, scene);
  REQUIRE(Differing(expected, unattenuated, 1e-3f) > expected.size() / 2);
  for (size_t i = 0; i < expected.size(); ++i)
  {
    for (int c = 0; c < 3; ++c) REQUIRE(expected[i][c] <= unattenuated[i][c] + 1e-6f);
    REQUIRE(expected[i].w == unattenuated[i].w);
  }

  auto cpu = CreateCallableShading_CPU();
  cpu->m_materials = palette;
  REQUIRE(Differing(render(*cpu), expected, 0.0f) == 0);
#ifdef CROSSRT_HAS_ISPC
  auto lanes = CreateCallableShading_ISPC();  // level 3 on the CPU: the switch, lane by lane
  lanes->m_materials = palette;
  REQUIRE(Differing(render(*lanes), expected, 1e-5f) == 0);
#endif

  if (!ctx) return;
  auto gpu = CreateCallableShading_Vulkan(ctx);
  auto& vulkan = dynamic_cast<CallableShading_Vulkan&>(*gpu);
  gpu->m_materials = palette;
  // Callable shaders by default wherever the device can run them.
  REQUIRE(vulkan.UsesRayTracingPipelines() == ctx->hasRayTracingPipeline);
  REQUIRE(Differing(render(*gpu), expected, 1e-5f) == 0);
  if (ctx->hasRayTracingPipeline)
  {
    vulkan.UseRayTracingPipelines(false);  // the same kernel as a compute shader with the switch
    REQUIRE(Differing(render(*gpu), expected, 1e-5f) == 0);
  }
  else
  {
    REQUIRE_THROWS_WITH(vulkan.UseRayTracingPipelines(true), Catch::Contains("has no ray tracing pipelines"));
    REQUIRE_FALSE(vulkan.UsesRayTracingPipelines());
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Virtual functions: pipelines made for the classes the objects hold give the same results, and are made again when those change",
          "[equivalence][virtual]")
{
  auto ctx = ValidatedContext();
  if (!ctx)
    return;  // no Vulkan device: the generated class cannot run
  std::vector<std::shared_ptr<IMaterial>> lamberts;
  for (auto& m : Palette())
    if (dynamic_cast<Lambert*>(m.get()))
      lamberts.push_back(m);
  const Scene scene = RandomScene(4001, uint32_t(lamberts.size()), 5);
  MaterialShading original;
  original.m_materials = lamberts;
  const auto expected = ShadeWith(original, scene);

  auto gpu = CreateMaterialShading_Vulkan(ctx);
  auto& vulkan = dynamic_cast<MaterialShading_Vulkan&>(*gpu);
  REQUIRE(vulkan.SpecializesVirtualCalls());  // the default
  gpu->m_materials = lamberts;  // pipelines with the Lambert cases only
  REQUIRE(Differing(ShadeWith(*gpu, scene), expected, 1e-5f) == 0);
  vulkan.SpecializeVirtualCalls(false);  // every case
  REQUIRE(Differing(ShadeWith(*gpu, scene), expected, 1e-5f) == 0);
  vulkan.SpecializeVirtualCalls(true);
  REQUIRE(Differing(ShadeWith(*gpu, scene), expected, 1e-5f) == 0);

  // Phongs and Checkers join the Lamberts in place (same size): CommitDeviceData() makes the
  // pipelines again, or their cases would still be dead code and shade nothing.
  const auto palette = Palette();
  gpu->m_materials.assign(palette.begin(), palette.begin() + lamberts.size());
  original.m_materials = gpu->m_materials;
  gpu->CommitDeviceData();
  const Scene mixed = RandomScene(4001, uint32_t(lamberts.size()), 6);
  const auto expectedMixed = ShadeWith(original, mixed);
  REQUIRE(Differing(ShadeWith(*gpu, mixed), expectedMixed, 1e-5f) == 0);
  RequireNoValidationMessages(ctx);
}
