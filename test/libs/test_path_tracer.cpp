// litept's path tracer: the Cornell box that scripts/make-cornell-box.py writes, rendered by the class
// as written, PathTracer_CPU, PathTracer_ISPC (where built) and PathTracer_Vulkan (both modes) with a fixed seed; an emitter seen
// directly; sphere and rectangle lights and what they hide; white furnaces; and scene files that cannot be read.
#include "PathTracer.h"
#include "PathTracer_CPU.h"
#include "PathTracer_Vulkan.h"
#ifdef CROSSRT_LITEPT_ISPC
#include "PathTracer_ISPC.h"
#endif
#include "SceneLoader.h"
#include "TestSupport.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

using namespace LiteMath;

namespace {

const std::string kCornellBox = CROSSRT_BINARY_DIR "/data/scenes/cornell_box.gltf";

std::vector<float4> Render(PathTracer& tracer, const PathScene& scene, const char* accel, uint32_t w, uint32_t h, int spp, int depth)
{
  tracer.SetScene(scene, MakeSceneRT(accel));
  tracer.SetImageAspect(float(w) / float(h));
  tracer.SetMaxDepth(depth);
  tracer.SetSeed(7);
  tracer.CommitDeviceData();
  // Passes of 1 spp: llvmpipe ends a shader invocation's loops after 65535 iterations in all, which a
  // megakernel of many samples reaches (VulkanContext::loopIterationLimit).
  std::vector<float4> out(size_t(w) * h, float4(0.0f)), pass(out.size());
  for (int sample = 0; sample < spp; ++sample)
  {
    tracer.RenderPass(w, h, uint32_t(sample), 1, pass.data());
    for (size_t i = 0; i < out.size(); ++i)
      out[i] += pass[i];
  }
  for (auto& v : out)
    v = v * (1.0f / float(spp));
  return out;
}

// Pixels with a channel that differs by more than rel (relative above 1, absolute below).
size_t Mismatches(const std::vector<float4>& expected, const std::vector<float4>& actual, float rel)
{
  size_t bad = 0;
  for (size_t i = 0; i < expected.size(); ++i)
    bad += !Close(expected[i].x, actual[i].x, rel) || !Close(expected[i].y, actual[i].y, rel) || !Close(expected[i].z, actual[i].z, rel);
  return bad;
}

size_t NonFinite(const std::vector<float4>& image)
{
  size_t bad = 0;
  for (const auto& v : image)
    bad += !std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z);
  return bad;
}

// A UV sphere of radius r, smooth normals.
PathScene::Mesh Sphere(float r, int segments, int rings)
{
  PathScene::Mesh m;
  m.name = "sphere";
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j)
    {
      const float theta = litept::kPi * float(i) / float(rings), phi = 2.0f * litept::kPi * float(j) / float(segments);
      const float3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      m.positions.push_back(to_float4(n * r, 1.0f));
      m.normals.push_back(to_float4(n, 0.0f));
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j)
    {
      const uint32_t a = uint32_t(i * (segments + 1) + j), b = a + uint32_t(segments + 1);
      for (uint32_t v : {a, b, a + 1, a + 1, b, b + 1})
        m.indices.push_back(v);
      m.triangleMaterial.push_back(0);
      m.triangleMaterial.push_back(0);
    }
  return m;
}

// A sphere of one material inside a uniform environment of radiance 1, seen from outside.
PathScene Furnace(std::shared_ptr<litept::IMaterial> material)
{
  PathScene s;
  s.meshes.push_back(Sphere(1.0f, 48, 24));
  s.instances.push_back({0, float4x4()});
  s.materials.push_back(std::move(material));
  s.environment = LiteImage::Image2D<float4>(1, 1, float4(1.0f));
  s.camera.position = float3(0.0f, 0.0f, 4.0f);
  s.camera.yfov = 0.5f;  // the sphere fills the middle of the image
  s.hasCamera = true;
  return s;
}

// The mean over the pixels whose camera ray hits the sphere's middle (the central quarter of the image).
float CentreMean(const std::vector<float4>& image, uint32_t side)
{
  double sum = 0.0;
  int n = 0;
  for (uint32_t y = side * 3 / 8; y < side * 5 / 8; ++y)
    for (uint32_t x = side * 3 / 8; x < side * 5 / 8; ++x)
    {
      const float4 v = image[y * side + x];
      sum += (v.x + v.y + v.z) / 3.0f;
      ++n;
    }
  return float(sum / n);
}

}  // namespace

TEST_CASE("path tracer: the Cornell box on the class as written, PathTracer_CPU and PathTracer_Vulkan agree", "[path_tracer]")
{
  PathScene scene = LoadScene(kCornellBox);
  ApplySceneDefaults(scene);
  REQUIRE(scene.notes.empty());  // a camera and lights of its own
  const uint32_t w = 24, h = 24;
  const int spp = 2, depth = 4;
  PathTracer original;
  const std::vector<float4> reference = Render(original, scene, "sah", w, h, spp, depth);
  REQUIRE(NonFinite(reference) == 0);
  double mean = 0.0;
  for (const auto& v : reference)
    mean += v.y;
  REQUIRE(mean / double(w * h) > 0.05);  // lit

  // On the CPU the same paths give the same numbers, through either ray tracer.
  auto cpu = CreatePathTracer_CPU();
  REQUIRE(Mismatches(reference, Render(*cpu, scene, "sah", w, h, spp, depth), 1e-5f) == 0);
  const std::vector<float4> embree = Render(*cpu, scene, "embree", w, h, spp, depth);
  // Embree's hits differ from BVHScene's in the last bits: a path may rarely take another way.
  REQUIRE(Mismatches(reference, embree, 1e-3f) <= reference.size() / 50);
#ifdef CROSSRT_LITEPT_ISPC
  // PathTracer_ISPC runs the thread loop in SIMD lanes, one path a lane, BVHScene's traversal
  // composed in: the same paths, the same numbers.
  auto ispc = CreatePathTracer_ISPC();
  REQUIRE(Mismatches(reference, Render(*ispc, scene, "sah", w, h, spp, depth), 1e-5f) == 0);
#endif

  auto ctx = ValidatedContext();
  if (!ctx)
    return;
  for (auto mode : {crossrt::ExecutionMode::Megakernel, crossrt::ExecutionMode::Wavefront})
  {
    PathTracer_Vulkan gpu(ctx);
    gpu.SetExecutionMode(mode);
    const std::vector<float4> image = Render(gpu, scene, "sah", w, h, spp, depth);
    INFO((mode == crossrt::ExecutionMode::Megakernel ? "megakernel" : "wavefront"));
    REQUIRE(NonFinite(image) == 0);
    // Lavapipe rounds as the CPU does; a GPU's last bits may send a rare path elsewhere.
    REQUIRE(Mismatches(reference, image, 1e-3f) <= (RoundsLikeTheCpu(*ctx) ? 0u : reference.size() / 50));
    RequireNoValidationMessages(ctx);
  }
}

TEST_CASE("path tracer: an emitter seen directly gives exactly its radiance", "[path_tracer]")
{
  PathScene scene = LoadScene(kCornellBox);
  ApplySceneDefaults(scene);
  // Aim at the light's centre with a narrow field of view: every camera ray hits it.
  scene.camera.position = float3(0.0f, 1.0f, 0.0f);
  scene.camera.forward = float3(0.0f, 1.0f, 0.0f);
  scene.camera.up = float3(0.0f, 0.0f, -1.0f);
  scene.camera.yfov = 0.05f;
  auto cpu = CreatePathTracer_CPU();
  for (int depth : {0, 3})
  {
    const std::vector<float4> image = Render(*cpu, scene, "embree", 8, 8, 4, depth);
    for (const auto& v : image)
    {
      // glTF: emissiveFactor (1, 0.85, 0.6) x KHR_materials_emissive_strength 17.
      REQUIRE(v.x == Approx(17.0f).epsilon(1e-6));
      REQUIRE(v.y == Approx(14.45f).epsilon(1e-6));
      REQUIRE(v.z == Approx(10.2f).epsilon(1e-6));
    }
  }
}

// A white Lambert (material 0), and a black one (material 1) emitting `radiance` from its front.
std::vector<std::shared_ptr<litept::IMaterial>> WhiteAndEmitter(float radiance)
{
  auto white = std::make_shared<litept::Lambert>();
  white->albedo = float4(1.0f);
  auto emitter = std::make_shared<litept::Lambert>();
  emitter->albedo = float4(0.0f);
  emitter->emission = float4(radiance, radiance, radiance, 0.0f);
  return {white, emitter};
}

// The camera straight above the origin at `height`, looking down (the image's up: -z).
void LookDown(PathScene& scene, float height, float yfov)
{
  scene.camera.position = float3(0.0f, height, 0.0f);
  scene.camera.forward = float3(0.0f, -1.0f, 0.0f);
  scene.camera.up = float3(0.0f, 0.0f, -1.0f);
  scene.camera.yfov = yfov;
  scene.hasCamera = true;
}

// Irradiance at p (normal n) from a polygon of uniform radiance L: Lambert's formula, the sum over
// its edges of the angle each subtends times the cosine of that edge's plane with n, over 2.
float PolygonIrradiance(float3 p, float3 n, const std::vector<float3>& polygon, float L)
{
  double sum = 0.0;
  for (size_t i = 0; i < polygon.size(); ++i)
  {
    const float3 a = normalize(polygon[i] - p), b = normalize(polygon[(i + 1) % polygon.size()] - p);
    sum += std::acos(std::clamp(dot(a, b), -1.0f, 1.0f)) * dot(normalize(cross(a, b)), n);
  }
  return float(std::fabs(sum) * 0.5 * L);
}

TEST_CASE("path tracer: an area light seen obliquely lights a Lambert floor as Lambert's formula says", "[path_tracer]")
{
  // A white Lambert floor (y = 0) and a small square emitter facing down at (1, 0.5, 0), seen from
  // the floor's middle 63 degrees off the normal. The camera looks straight down at a small patch.
  // Shadow rays used to run parallel to the light's direction from a point lifted off the floor, so
  // at such angles they met the light's plane before the sampled point and hit the light itself.
  PathScene scene;
  PathScene::Mesh quads;
  quads.name = "floor and light";
  const float3 floor[4] = {float3(-2, 0, -2), float3(-2, 0, 2), float3(2, 0, 2), float3(2, 0, -2)};
  const std::vector<float3> light = {float3(0.9f, 0.5f, -0.1f), float3(1.1f, 0.5f, -0.1f), float3(1.1f, 0.5f, 0.1f), float3(0.9f, 0.5f, 0.1f)};
  for (int q = 0; q < 2; ++q)
  {
    const uint32_t first = uint32_t(quads.positions.size());
    for (int i = 0; i < 4; ++i)
    {
      quads.positions.push_back(to_float4(q == 0 ? floor[i] : light[size_t(i)], 1.0f));
      quads.normals.push_back(float4(0.0f, q == 0 ? 1.0f : -1.0f, 0.0f, 0.0f));
    }
    for (uint32_t v : {0u, 1u, 2u, 0u, 2u, 3u})
      quads.indices.push_back(first + v);
    quads.triangleMaterial.push_back(uint32_t(q));
    quads.triangleMaterial.push_back(uint32_t(q));
  }
  scene.meshes.push_back(quads);
  scene.instances.push_back({0, float4x4()});
  scene.materials = WhiteAndEmitter(10.0f);
  LookDown(scene, 3.0f, 0.02f);  // a 6 cm patch of floor

  // Outgoing radiance of an albedo-1 Lambert: E / pi, over the patch (E varies by 2% across it).
  double expected = 0.0;
  for (float z = -0.03f; z <= 0.03f; z += 0.005f)
    for (float x = -0.03f; x <= 0.03f; x += 0.005f)
      expected += PolygonIrradiance(float3(x, 0.0f, z), float3(0.0f, 1.0f, 0.0f), light, 10.0f) / litept::kPi;
  expected /= 13.0 * 13.0;

  auto cpu = CreatePathTracer_CPU();
  const std::vector<float4> image = Render(*cpu, scene, "embree", 8, 8, 1024, 0);
  double mean = 0.0;
  for (const auto& v : image)
    mean += (v.x + v.y + v.z) / 3.0;
  mean /= double(image.size());
  INFO("rendered " << mean << ", Lambert's formula " << expected);
  CHECK(mean == Approx(expected).epsilon(0.01));
}

TEST_CASE("path tracer: sphere and rectangle lights from glTF light extras light a floor as the formulas say, and hide what is behind them", "[path_tracer]")
{
  // A white Lambert floor (KHR_materials_specular factor 0), and two point lights of intensity 2 at
  // (0, 1, 0) with sizes in their extras: a sphere of radius 0.1, and a 0.4 x 0.2 rectangle turned to
  // face down. Each is rendered alone, direct light only.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "crossrt_shape_lights";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "lights.gltf") << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1,2]}],
    "extensionsUsed":["KHR_lights_punctual","KHR_materials_specular"],
    "extensions":{"KHR_lights_punctual":{"lights":[
      {"type":"point","color":[1,1,1],"intensity":2,"extras":{"radius":0.1}},
      {"type":"point","color":[1,1,1],"intensity":2,"extras":{"width":0.4,"height":0.2}}]}},
    "nodes":[{"mesh":0},
             {"translation":[0,1,0],"extensions":{"KHR_lights_punctual":{"light":0}}},
             {"translation":[0,1,0],"rotation":[-0.70710678,0,0,0.70710678],"extensions":{"KHR_lights_punctual":{"light":1}}}],
    "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"material":0}]}],
    "materials":[{"pbrMetallicRoughness":{"baseColorFactor":[1,1,1,1],"metallicFactor":0},
                  "extensions":{"KHR_materials_specular":{"specularFactor":0}}}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-4,0,-4],"max":[4,0,4]},
                 {"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}],
    "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12}],
    "buffers":[{"byteLength":60,"uri":"data:application/octet-stream;base64,AACAwAAAAAAAAIDAAACAwAAAAAAAAIBAAACAQAAAAAAAAIBAAACAQAAAAAAAAIDAAAABAAIAAAACAAMA"}]})";
  const PathScene loaded = LoadScene((dir / "lights.gltf").string());
  std::filesystem::remove_all(dir);
  REQUIRE(loaded.lights.size() == 2u);
  REQUIRE(dynamic_cast<const litept::SphereLight*>(loaded.lights[0].get()) != nullptr);
  REQUIRE(dynamic_cast<const litept::RectLight*>(loaded.lights[1].get()) != nullptr);

  const float intensity = 2.0f / 683.0f;  // glTF's candelas in W/sr, as Blender's importer converts them
  const float sphereRadiance = intensity / (litept::kPi * 0.01f), rectRadiance = intensity / 0.08f;
  const std::vector<float3> rect = {float3(-0.2f, 1, -0.1f), float3(0.2f, 1, -0.1f), float3(0.2f, 1, 0.1f), float3(-0.2f, 1, 0.1f)};
  const float expected[2] = {
      sphereRadiance * 0.01f,                                                           // E / pi = L sin^2 of the cone, below its centre
      PolygonIrradiance(float3(0.0f), float3(0.0f, 1.0f, 0.0f), rect, rectRadiance) / litept::kPi};  // Lambert's formula
  auto cpu = CreatePathTracer_CPU();
  for (int which = 0; which < 2; ++which)
  {
    PathScene scene = loaded;
    scene.lights = {loaded.lights[size_t(which)]};
    // The floor's middle, seen obliquely from the side with a narrow view (the patch is 3 cm long).
    scene.camera.position = float3(3.0f, 1.5f, 0.0f);
    scene.camera.forward = normalize(float3(-3.0f, -1.5f, 0.0f));
    scene.camera.up = normalize(float3(-1.5f, 3.0f, 0.0f));
    scene.camera.yfov = 0.004f;
    scene.hasCamera = true;
    const std::vector<float4> lit = Render(*cpu, scene, "embree", 8, 8, 1024, 0);
    double mean = 0.0;
    for (const auto& v : lit)
      mean += v.y / double(lit.size());
    INFO((which == 0 ? "sphere" : "rectangle") << ": rendered " << mean << ", expected " << expected[which]);
    CHECK(mean == Approx(expected[which]).epsilon(0.01));
    // Seen directly from below, each gives its radiance; the rectangle's back is dark.
    scene.camera.position = float3(0.0f, 0.5f, 0.0f);
    scene.camera.forward = float3(0.0f, 1.0f, 0.0f);
    scene.camera.up = float3(0.0f, 0.0f, -1.0f);
    scene.camera.yfov = 0.01f;
    const std::vector<float4> seen = Render(*cpu, scene, "embree", 4, 4, 4, 0);
    CHECK(seen[5].y == Approx(which == 0 ? sphereRadiance : rectRadiance).epsilon(1e-5));
    scene.camera.position = float3(0.0f, 1.5f, 0.0f);
    scene.camera.forward = float3(0.0f, -1.0f, 0.0f);
    const std::vector<float4> above = Render(*cpu, scene, "embree", 4, 4, 4, 0);
    if (which == 1)
      CHECK(above[5].y == 0.0f);
  }

  // A dim sphere light (radius 0.3 at height 0.5) between the floor's middle and a bright rectangle:
  // the sphere hides the rectangle, so the floor there gets the sphere's light alone, on every backend.
  auto sphere = std::make_shared<litept::SphereLight>(*dynamic_cast<const litept::SphereLight*>(loaded.lights[0].get()));
  auto bright = std::make_shared<litept::RectLight>(*dynamic_cast<const litept::RectLight*>(loaded.lights[1].get()));
  sphere->centerRadius = float4(0.0f, 0.5f, 0.0f, 0.3f);
  sphere->radiance = float4(0.1f, 0.1f, 0.1f, 0.0f);
  bright->radiance = float4(10.0f, 10.0f, 10.0f, 0.0f);  // unhidden, it would add about 0.25
  PathScene hidden = loaded;
  hidden.lights = {sphere, bright};
  hidden.camera.position = float3(3.0f, 1.5f, 0.0f);
  hidden.camera.forward = normalize(float3(-3.0f, -1.5f, 0.0f));
  hidden.camera.up = normalize(float3(-1.5f, 3.0f, 0.0f));
  hidden.camera.yfov = 0.004f;
  hidden.hasCamera = true;
  const double sphereOnly = 0.1 * 0.6 * 0.6;  // L sin^2 of the cone (sin = 0.3 / 0.5)
  auto gpu = CreatePathTracer_Vulkan();
  for (PathTracer* tracer : {static_cast<PathTracer*>(cpu.get()), static_cast<PathTracer*>(gpu.get())})
  {
    const std::vector<float4> lit = Render(*tracer, hidden, "sah", 8, 8, 256, 0);
    double mean = 0.0;
    for (const auto& v : lit)
      mean += v.y / double(lit.size());
    INFO((tracer == cpu.get() ? "PathTracer_CPU" : "PathTracer_Vulkan") << ": rendered " << mean << ", the sphere alone " << sphereOnly);
    CHECK(mean == Approx(sphereOnly).epsilon(0.02));
  }
}

TEST_CASE("path tracer: degenerate triangles and zero normals put no NaN or inf in the image", "[path_tracer]")
{
  // A floor lit by a small area light, and in view: a quad whose vertex normals are all zero (as
  // broken files have them), triangles with a repeated corner or collinear corners, a sliver of
  // area 1e-12, and an emitter of zero area (which cannot be sampled).
  PathScene scene;
  PathScene::Mesh m;
  m.name = "degenerate";
  auto triangle = [&](float3 a, float3 b, float3 c, float3 normal, uint32_t material) {
    for (float3 p : {a, b, c})
    {
      m.indices.push_back(uint32_t(m.positions.size()));
      m.positions.push_back(to_float4(p, 1.0f));
      m.normals.push_back(to_float4(normal, 0.0f));
    }
    m.triangleMaterial.push_back(material);
  };
  const float3 up(0.0f, 1.0f, 0.0f), down(0.0f, -1.0f, 0.0f), zero(0.0f);
  triangle(float3(-2, 0, -2), float3(-2, 0, 2), float3(2, 0, 2), up, 0);  // the floor
  triangle(float3(-2, 0, -2), float3(2, 0, 2), float3(2, 0, -2), up, 0);
  triangle(float3(-0.2f, 1, -0.2f), float3(0.2f, 1, -0.2f), float3(0.2f, 1, 0.2f), down, 1);  // the light
  triangle(float3(-0.2f, 1, -0.2f), float3(0.2f, 1, 0.2f), float3(-0.2f, 1, 0.2f), down, 1);
  triangle(float3(-1, 0.2f, -1), float3(-1, 0.2f, 0), float3(1, 0.2f, 0), zero, 0);  // zero normals
  triangle(float3(-1, 0.2f, -1), float3(1, 0.2f, 0), float3(1, 0.2f, -1), zero, 0);
  triangle(float3(0.5f, 0.1f, 0.5f), float3(0.5f, 0.1f, 0.5f), float3(1, 0.1f, 1), up, 0);     // a repeated corner
  triangle(float3(0.2f, 0.1f, 0.2f), float3(0.6f, 0.1f, 0.6f), float3(1.4f, 0.1f, 1.4f), up, 0);  // collinear
  triangle(float3(0.3f, 0.3f, -0.5f), float3(1.3f, 0.3f, -0.5f), float3(0.8f, 0.3f, -0.5f + 1e-12f), zero, 0);  // a sliver
  triangle(float3(0.5f, 0.9f, 0.5f), float3(0.5f, 0.9f, 0.5f), float3(0.7f, 0.9f, 0.7f), down, 1);  // an emitter of no area
  scene.meshes.push_back(m);
  scene.instances.push_back({0, float4x4()});
  scene.materials = WhiteAndEmitter(20.0f);
  LookDown(scene, 3.0f, 1.0f);

  PathTracer original;
  auto cpu = CreatePathTracer_CPU();
  const std::vector<float4> bvh = Render(original, scene, "sah", 32, 32, 16, 4);
  const std::vector<float4> embree = Render(*cpu, scene, "embree", 32, 32, 16, 4);
  CHECK(NonFinite(bvh) == 0);
  CHECK(NonFinite(embree) == 0);
  // The zero-normal quad is lit (it shades with its geometric normal), not black.
  const float4 patch = bvh[size_t(32 * 12 + 12)];
  CHECK(patch.x > 0.01f);
}

TEST_CASE("path tracer: white furnaces: what each material keeps of a uniform environment", "[path_tracer]")
{
  auto cpu = CreatePathTracer_CPU();
  const uint32_t side = 32;
  struct Case
  {
    const char* name;
    std::shared_ptr<litept::IMaterial> material;
    float lo, hi;  // the mean's bounds: energy lost by design below 1 (single scattering), none gained
  };
  auto lambert = std::make_shared<litept::Lambert>();
  lambert->albedo = float4(1.0f);
  auto glass = std::make_shared<litept::Dielectric>();
  auto roughGlass = std::make_shared<litept::Dielectric>();
  roughGlass->alpha = 0.25f;
  auto metal = std::make_shared<litept::GltfMetalRough>();
  metal->baseColor = float4(1.0f);
  metal->roughness = 0.5f;
  auto dielectricLayer = std::make_shared<litept::GltfMetalRough>();
  dielectricLayer->baseColor = float4(1.0f);
  dielectricLayer->metallic = 0.0f;
  dielectricLayer->roughness = 0.5f;
  auto conductor = std::make_shared<litept::RoughConductor>();
  conductor->eta = float4(0.0f);
  conductor->k = float4(1e4f);  // a perfect reflector: F = 1
  conductor->alpha = 0.25f;
  const Case cases[] = {
      {"Lambert, albedo 1", lambert, 0.99f, 1.01f},
      {"smooth glass", glass, 0.98f, 1.01f},
      // Single-scattering microfacet lobes lose what would scatter again between the facets. A
      // quadrature of GGX with height-correlated Smith at alpha 0.25 gives an albedo of 0.916 at
      // normal incidence and 0.913 at 14.5 degrees (the centre's steepest): so the conductor.
      {"rough conductor, F = 1, alpha 0.25", conductor, 0.90f, 0.93f},
      {"glTF metal, white, roughness 0.5 (alpha 0.25)", metal, 0.90f, 0.93f},
      // The dielectric layer's specular lobe loses like the conductor's, on 4% of the light.
      {"glTF dielectric over white, roughness 0.5", dielectricLayer, 0.97f, 1.01f},
      // Reflection and transmission both lose, and light crosses the rough surface twice or more.
      {"rough glass, alpha 0.25", roughGlass, 0.85f, 0.95f},
  };
  for (const Case& c : cases)
  {
    const std::vector<float4> image = Render(*cpu, Furnace(c.material), "embree", side, side, 64, 32);
    INFO(c.name);
    REQUIRE(NonFinite(image) == 0);
    const float mean = CentreMean(image, side);
    CHECK(mean >= c.lo);
    CHECK(mean <= c.hi);
  }
}

TEST_CASE("path tracer: a glTF scene's PNG and JPEG textures load, base colour linearised from sRGB", "[path_tracer]")
{
  // A quad in the xy plane whose base colour (and normal map) is a 2x2 PNG and whose emission is a
  // flat 8x8 JPEG, written here. Its texture coordinates put the image's top at y = 1 (glTF's v runs
  // down the image).
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "crossrt_textured_scene";
  std::filesystem::create_directories(dir);
  LiteImage::Image2D<float4> png(2, 2);
  png[int2(0, 0)] = float4(1.0f, 0.0f, 0.0f, 1.0f);
  png[int2(1, 0)] = float4(0.0f, 1.0f, 0.0f, 1.0f);
  png[int2(0, 1)] = float4(0.0f, 0.0f, 1.0f, 1.0f);
  png[int2(1, 1)] = float4(128.0f / 255.0f, 128.0f / 255.0f, 128.0f / 255.0f, 1.0f);
  REQUIRE(LiteImage::SaveImage((dir / "base.png").string().c_str(), png));
  REQUIRE(LiteImage::SaveImage((dir / "glow.jpg").string().c_str(), LiteImage::Image2D<float4>(8, 8, float4(1.0f, 1.0f, 1.0f, 1.0f))));
  // Four positions (vec3), six indices (uint16) and four texture coordinates (vec2), base64.
  std::ofstream(dir / "quad.gltf") << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
    "meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":2},"indices":1,"material":0}]}],
    "materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}},"emissiveTexture":{"index":1},"emissiveFactor":[1,1,1],
                  "normalTexture":{"index":0}}],
    "textures":[{"source":0},{"source":1}],"images":[{"uri":"base.png"},{"uri":"glow.jpg"}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
                 {"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"},
                 {"bufferView":2,"componentType":5126,"count":4,"type":"VEC2"}],
    "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12},
                   {"buffer":0,"byteOffset":60,"byteLength":32}],
    "buffers":[{"byteLength":92,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAAgD8AAAAAAAAAAAAAgD8AAAAAAAABAAIAAAACAAMAAAAAAAAAgD8AAIA/AACAPwAAgD8AAAAAAAAAAAAAAAA="}]})";
  const PathScene scene = LoadScene((dir / "quad.gltf").string());
  REQUIRE(scene.meshes.size() == 1u);
  const int4 ids = scene.materials.at(scene.meshes[0].triangleMaterial.at(0))->TextureIds();  // colour, metal-rough, normal, emission
  REQUIRE(ids.x >= 0);
  REQUIRE(ids.w >= 0);
  REQUIRE(scene.textures.size() == 3u);  // base.png twice: as sRGB colour and as a linear normal map
  const auto& base = scene.textures[size_t(ids.x)];
  REQUIRE(base.width() == 2u);
  REQUIRE(base.height() == 2u);
  CHECK(base[int2(0, 0)].x == Approx(1.0f));
  CHECK(base[int2(0, 0)].y == Approx(0.0f).margin(1e-6));
  CHECK(base[int2(1, 0)].y == Approx(1.0f));
  CHECK(base[int2(0, 1)].z == Approx(1.0f));
  CHECK(base[int2(1, 1)].x == Approx(0.2158605f).epsilon(1e-3));  // sRGB 128 in linear
  const auto& glow = scene.textures[size_t(ids.w)];
  REQUIRE(glow.width() == 8u);
  CHECK(glow[int2(3, 3)].x == Approx(1.0f).margin(2.0f / 255.0f));
  // Tangents computed for the normal map: along +u (x), and the bitangent glTF defines,
  // cross(normal, tangent) * w, along the image's up, where the map's green axis points (+y).
  REQUIRE(scene.meshes[0].tangents.size() == scene.meshes[0].positions.size());
  for (size_t i = 0; i < scene.meshes[0].tangents.size(); ++i)
  {
    const float4 t = scene.meshes[0].tangents[i];
    const float3 bitangent = cross(to_float3(scene.meshes[0].normals[i]), to_float3(t)) * t.w;
    CHECK(t.x == Approx(1.0f));
    CHECK(bitangent.y == Approx(1.0f));
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("path tracer: scene files that cannot be read give a clear error", "[path_tracer]")
{
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "crossrt_path_tracer_test";
  std::filesystem::create_directories(dir);
  auto message = [](const std::string& path) {
    try
    {
      LoadScene(path);
    }
    catch (const SceneError& e)
    {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  CHECK_THAT(message((dir / "missing.gltf").string()), Catch::Contains("missing.gltf: error: no such file"));
  std::ofstream(dir / "broken.gltf") << "{ \"asset\": { \"version\": \"2.0\" }, \"meshes\": [ { ";
  CHECK_THAT(message((dir / "broken.gltf").string()), Catch::Contains("broken.gltf: error: not a readable glTF 2.0 file"));
  std::ofstream(dir / "scene.ply") << "ply\n";
  CHECK_THAT(message((dir / "scene.ply").string()), Catch::Contains("unknown scene format '.ply'"));
  // A texture whose image file is missing.
  std::ofstream(dir / "textured.gltf") << R"({"asset":{"version":"2.0"},"images":[{"uri":"nowhere.png"}],"textures":[{"source":0}],
    "materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}]})";
  CHECK_THAT(message((dir / "textured.gltf").string()), Catch::Contains("textured.gltf: error:"));
  // No triangles at all.
  std::ofstream(dir / "empty.gltf") << R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[]}]})";
  CHECK_THAT(message((dir / "empty.gltf").string()), Catch::Contains("the scene has no triangles"));
  std::filesystem::remove_all(dir);
}
