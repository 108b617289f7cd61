// The composed traversal specialised to the scene (BVHScene::m_sceneKinds, CRT_SPECIALIZE): what a
// scene's first frame and its later frames cost on Vulkan when the traversal shader is compiled for
// the kinds of geometry the scene holds, against the same shader compiled for every kind (BVHScene's
// boxes, signed distance fields and motion included), which is what every scene got before.
//
// PrimaryRays_Vulkan renders MESH with ambient occlusion through BVHScene's translated traversal (ray
// queries off: the path of a GPU without them) in three scenes:
//   - the mesh alone, at the identity;
//   - an outside AO renderer's scene: three instances of the mesh and a ground quad;
//   - that scene with m_sceneKinds set to every kind: the traversal unspecialised.
// A first frame makes the pipelines; the driver's shader cache (MESA_SHADER_CACHE_DISABLE) and
// CrossRT's pipeline cache (a fresh CROSSRT_PIPELINE_CACHE_DIR) are off, as on a user's first run.
// Later frames are measured in interleaved rounds, each scene in its own PrimaryRays_Vulkan.
// Prints a table with the CPU model and the device, writes CSV (default out/bench_specialize.csv),
// which bench/plot_specialize.py plots. On lavapipe, which compiles and runs shaders on the CPU,
// only the ratios mean anything.
#include "BenchSupport.h"
#include "CommandLine.h"
#include "MeshIO.h"
#include "PrimaryRays.h"
#include "PrimaryRays_Vulkan.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>

using namespace LiteMath;

namespace {

// A unit sphere of 2 * n * n triangles (the mesh when none is given).
TriangleMesh SphereMesh(int n)
{
  TriangleMesh m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= 2 * n; ++j)
    {
      const float theta = 3.14159265f * float(i) / float(n), phi = 3.14159265f * float(j) / float(n);
      m.positions.insert(m.positions.end(), {std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)});
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 2 * n; ++j)
    {
      const uint32_t a = uint32_t(i * (2 * n + 1) + j), b = a + uint32_t(2 * n + 1);
      m.indices.insert(m.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
  return m;
}

struct Scene
{
  const char* name;
  std::shared_ptr<ISceneObject> scene;
  uint32_t kinds = 0;
  std::shared_ptr<PrimaryRays_Vulkan> renderer;
  double firstFrameS = 0.0;
  std::vector<double> frameMs;
};

}  // namespace

int main(int argc, char** argv)
{
  std::string meshPath, csvPath = "out/bench_specialize.csv";
  int size = 256, ao = 4, rounds = 5;
  crossrt::CommandLine app("bench_specialize",
                           "First and later frames of PrimaryRays_Vulkan's translated traversal (ray queries off) with the\n"
                           "shader specialised to the scene's kinds of geometry (BVHScene::m_sceneKinds, CRT_SPECIALIZE), and\n"
                           "unspecialised: the mesh alone, three instances and a ground quad, and those with every kind. First\n"
                           "frames run with the driver's shader cache and CrossRT's pipeline cache off. Uses the default Vulkan\n"
                           "device (CROSSRT_DEVICE chooses another).");
  app.add_option("MESH", meshPath, "the mesh (OFF, PLY or OBJ; none: a sphere of 20,000 triangles)");
  app.add_option("--size", size, "width and height in pixels")->check(crossrt::Positive());
  app.add_option("--ao", ao, "ambient occlusion rays per pixel")->check(crossrt::NonNegative());
  app.add_option("--rounds", rounds, "interleaved rounds of later frames")->check(crossrt::Positive());
  app.add_option("--csv", csvPath, "the table's CSV file");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;

  // Cold: no shader cache of the driver's, a pipeline cache of CrossRT's that starts empty.
  const std::filesystem::path cacheDir = std::filesystem::temp_directory_path() / ("bench_specialize_" + std::to_string(::getpid()));
  setenv("MESA_SHADER_CACHE_DISABLE", "true", 1);
  setenv("CROSSRT_PIPELINE_CACHE_DIR", cacheDir.c_str(), 1);
  TriangleMesh mesh;
  std::shared_ptr<crossrt::VulkanContext> ctx;
  try
  {
    mesh = meshPath.empty() ? SphereMesh(100) : LoadMesh(meshPath);
    ctx = crossrt::VulkanContext::CreateDefault();
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "bench_specialize: %s\n", e.what());
    return 1;
  }
  float3 lo(1e30f), hi(-1e30f);
  for (size_t i = 0; i < mesh.VertexCount(); ++i)
  {
    const float3 p(mesh.positions[3 * i], mesh.positions[3 * i + 1], mesh.positions[3 * i + 2]);
    lo = min(lo, p), hi = max(hi, p);
  }
  const float3 centre = (lo + hi) * 0.5f;
  const float radius = length(hi - lo) * 0.5f;

  // The scenes: the mesh alone; three instances of it side by side and a ground quad under them.
  auto makeScene = [&](bool instances) {
    auto scene = MakeSceneRT("sah");
    const uint32_t g = scene->AddGeom_Triangles3f(mesh.positions.data(), mesh.VertexCount(), mesh.indices.data(), mesh.indices.size());
    if (!instances)
    {
      scene->AddInstance(g, float4x4());
      scene->CommitScene();
      return scene;
    }
    for (int k = -1; k <= 1; ++k)
      scene->AddInstance(g, translate4x4(float3(2.2f * radius * float(k), 0.0f, 0.0f)) * rotate4x4Y(0.6f * float(k)));
    const float w = 4.0f * radius, y = lo.y - centre.y;
    const float quad[12] = {-w, y, -w, w, y, -w, w, y, w, -w, y, w};
    const uint32_t quadIndices[6] = {0, 1, 2, 0, 2, 3};
    scene->AddInstance(scene->AddGeom_Triangles3f(quad, 4, quadIndices, 6), translate4x4(centre));
    scene->CommitScene();
    return scene;
  };
  std::vector<Scene> scenes = {{"the mesh alone", makeScene(false)},
                               {"3 instances and a ground quad", makeScene(true)},
                               {"the same, unspecialised (every kind)", makeScene(true)}};
  const uint32_t everyKind = kSceneTriangles | kSceneTransformed | kInstanceBoxes | kInstanceSdf | kInstanceMotion;
  dynamic_cast<BVHScene&>(*scenes[2].scene).m_sceneKinds = everyKind;  // a superset of the scene's: the code for all kinds stays
  std::vector<uint32_t> pixels(size_t(size) * size);
  try
  {
    for (Scene& s : scenes)
    {
      s.kinds = dynamic_cast<BVHScene&>(*s.scene).m_sceneKinds;
      s.renderer = std::make_shared<PrimaryRays_Vulkan>(ctx, size, size);
      s.renderer->UseRayTracingHardware(false);
      s.renderer->SetScene(s.scene, mesh.positions, mesh.indices);
      s.renderer->SetCamera(centre + float3(0.0f, 0.8f, 3.2f) * radius, centre, float3(0.0f, 1.0f, 0.0f), 50.0f);
      s.renderer->SetOcclusion(ao, radius * 0.3f);
      s.firstFrameS = Seconds([&] {
        s.renderer->CommitDeviceData();
        s.renderer->Render(pixels.data());
      });
      std::fprintf(stderr, "bench_specialize: %s: first frame %.2f s\n", s.name, s.firstFrameS);
    }
    std::vector<std::function<void()>> works;
    for (Scene& s : scenes)
      works.push_back([&] { s.renderer->Render(pixels.data()); });
    const auto ms = InterleavedMs(works, rounds);
    for (size_t i = 0; i < scenes.size(); ++i)
      scenes[i].frameMs = ms[i];
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "bench_specialize: %s\n", e.what());
    std::filesystem::remove_all(cacheDir);
    return 1;
  }
  std::filesystem::remove_all(cacheDir);

  std::printf("## The composed traversal specialised to the scene: PrimaryRays_Vulkan, software traversal\n\n");
  std::printf("CPU: %s; device: %s; %zu triangles a mesh, %dx%d pixels, %d AO rays a pixel, %d interleaved rounds.\n", CpuModel().c_str(),
              ctx->DeviceName().c_str(), mesh.TriangleCount(), size, size, ao, rounds);
  std::printf("First frame: making the pipelines (no shader or pipeline cache) and rendering. Ratios against the unspecialised\n"
              "shader in the same run%s.\n\n",
              ctx->DeviceName().find("llvmpipe") != std::string::npos ? "; lavapipe compiles and runs on the CPU, so only the ratios mean anything" : "");
  std::printf("| scene | m_sceneKinds | first frame (s) | vs unspecialised | later frame (ms) | vs unspecialised |\n|---|---|---|---|---|---|\n");
  std::filesystem::create_directories(std::filesystem::path(csvPath).parent_path().empty() ? "." : std::filesystem::path(csvPath).parent_path());
  std::ofstream csv(csvPath);
  if (!csv)
  {
    std::fprintf(stderr, "bench_specialize: cannot write %s\n", csvPath.c_str());
    return 1;
  }
  csv << "scene,scene_kinds,first_frame_s,first_frame_vs_unspecialised,frame_ms,frame_vs_unspecialised,cpu,device\n";
  const Scene& unspecialised = scenes.back();
  for (const Scene& s : scenes)
  {
    const double frame = MedianOf(s.frameMs), firstRatio = s.firstFrameS / unspecialised.firstFrameS;
    const double frameRatio = PairedRatio(s.frameMs, unspecialised.frameMs);
    std::printf("| %s | %u | %.2f | %.3fx | %.1f | %.3fx |\n", s.name, s.kinds, s.firstFrameS, firstRatio, frame, frameRatio);
    csv << "\"" << s.name << "\"," << s.kinds << "," << s.firstFrameS << "," << firstRatio << "," << frame << "," << frameRatio << ",\"" << CpuModel()
        << "\",\"" << ctx->DeviceName() << "\"\n";
  }
  std::printf("\nCSV: %s (bench/plot_specialize.py plots it)\n", csvPath.c_str());
  return 0;
}
