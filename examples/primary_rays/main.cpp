// Primary rays with ambient occlusion through ISceneObject: the class as written on Embree and on
// CrossRT's BVH, PrimaryRays_CPU (all cores), PrimaryRays_ISPC (all cores, a ray per SIMD lane;
// where ISPC was found at configure time) and PrimaryRays_Vulkan (the BVH traversal composed
// into the shader, and on devices with ray queries also the ray tracing hardware). Prints a table
// of times and of pixels that differ from the original on the same BVH, and writes the last image.
//   primary_rays [mesh file] [output image] [--size N] [--ao SAMPLES] [--bvh lbvh|sah]
// Without a mesh (or with "") it renders a built-in scene: a bumpy sphere on a floor.
#include "MeshIO.h"
#include "Image2D.h"
#include "PrimaryRays.h"
#include "PrimaryRays_CPU.h"
#include "PrimaryRays_Vulkan.h"
#ifdef CROSSRT_HAS_ISPC
#include "PrimaryRays_ISPC.h"
#endif

#include "CommandLine.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

using namespace LiteMath;

namespace {

TriangleMesh BuiltInScene()
{
  TriangleMesh mesh;
  const int rings = 64, segments = 128;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j)
    {
      const float theta = 3.14159265f * float(i) / rings, phi = 6.28318531f * float(j) / segments;
      const float3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      const float r = 0.8f * (1.0f + 0.15f * std::sin(6.0f * phi) * std::sin(5.0f * theta));
      mesh.positions.insert(mesh.positions.end(), {r * n.x, r * n.y + 0.1f, r * n.z});
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j)
    {
      const uint32_t a = uint32_t(i * (segments + 1) + j), b = a + 1, c = a + segments + 1, d = c + 1;
      mesh.indices.insert(mesh.indices.end(), {a, c, b, b, c, d});
    }
  const uint32_t base = uint32_t(mesh.VertexCount());
  const float y = -0.85f, s = 3.0f;
  mesh.positions.insert(mesh.positions.end(), {-s, y, -s, s, y, -s, s, y, s, -s, y, s});
  mesh.indices.insert(mesh.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
  return mesh;
}

struct Run
{
  std::string name;
  std::shared_ptr<PrimaryRays> renderer;
  std::vector<uint32_t> pixels;
  double ms = 0.0;
};

// Pixels whose channels differ by more than 2/255.
size_t DifferingPixels(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b)
{
  size_t count = 0;
  for (size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c)
      if (std::abs(int((a[i] >> (8 * c)) & 255u) - int((b[i] >> (8 * c)) & 255u)) > 2)
      {
        ++count;
        break;
      }
  return count;
}

}  // namespace

int main(int argc, char** argv)
{
  std::string meshPath, outPath = "primary_rays.png", bvh = "lbvh";
  int size = 512, ao = 4;
  bool hardwareOnly = false;
  crossrt::CommandLine app("primary_rays",
                           "Renders MESH (OFF, PLY or OBJ, also gzipped; \"\" or none: a built-in scene) with primary rays and\n"
                           "ambient occlusion through ISceneObject: Embree, the original class, PrimaryRays_CPU, PrimaryRays_ISPC\n"
                           "(where ISPC was found when CrossRT was configured) and PrimaryRays_Vulkan (its translated traversal,\n"
                           "and ray queries where the device has them).");
  app.add_option("MESH", meshPath, "the mesh (\"\": the built-in scene)");
  app.add_option("OUTPUT.png", outPath, "the image");
  app.add_option("--size", size, "width and height in pixels")->check(crossrt::Positive());
  app.add_option("--ao", ao, "ambient occlusion rays per pixel")->check(crossrt::NonNegative());
  app.add_option("--bvh", bvh, "the BVH the original and CPU classes build")->check(CLI::IsMember({"lbvh", "sah"}));
  app.add_flag("--hardware-only", hardwareOnly, "on Vulkan, ray queries only");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  TriangleMesh mesh;
  try
  {
    mesh = meshPath.empty() ? BuiltInScene() : LoadMesh(meshPath);
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "primary_rays: %s\n", e.what());
    return 1;
  }
  // Frame the mesh: the camera looks at its box centre from the front, slightly above.
  float3 lo(1e30f, 1e30f, 1e30f), hi(-1e30f, -1e30f, -1e30f);
  for (size_t i = 0; i < mesh.VertexCount(); ++i)
  {
    const float3 p(mesh.positions[3 * i], mesh.positions[3 * i + 1], mesh.positions[3 * i + 2]);
    lo = min(lo, p), hi = max(hi, p);
  }
  const float3 centre = (lo + hi) * 0.5f;
  const float radius = length(hi - lo) * 0.5f;
  const float3 eye = centre + float3(0.3f, 0.45f, 1.0f) * (radius * 1.9f);

  auto makeScene = [&](const char* impl) {
    auto scene = MakeSceneRT(impl);
    scene->AddInstance(scene->AddGeom_Triangles3f(mesh.positions.data(), mesh.VertexCount(), mesh.indices.data(), mesh.indices.size()),
                       float4x4());
    scene->CommitScene();
    return scene;
  };
  std::vector<Run> runs;
  try
  {
    auto bvhScene = makeScene(bvh.c_str());
    runs.push_back({"original, " + bvh + " (1 thread)", std::make_shared<PrimaryRays>(size, size), {}});
    runs.back().renderer->SetScene(bvhScene, mesh.positions, mesh.indices);
    runs.push_back({"original, embree (1 thread)", std::make_shared<PrimaryRays>(size, size), {}});
    runs.back().renderer->SetScene(makeScene("embree"), mesh.positions, mesh.indices);
    runs.push_back({"PrimaryRays_CPU, " + bvh, CreatePrimaryRays_CPU(size, size), {}});
    runs.back().renderer->SetScene(bvhScene, mesh.positions, mesh.indices);
#ifdef CROSSRT_HAS_ISPC
    runs.push_back({"PrimaryRays_ISPC, " + bvh, CreatePrimaryRays_ISPC(size, size), {}});
    runs.back().renderer->SetScene(bvhScene, mesh.positions, mesh.indices);
#else
    std::printf("CrossRT was configured without ISPC: no PrimaryRays_ISPC\n");
#endif
    try
    {
      // The translated traversal, and where the device has ray queries its ray tracing hardware.
      auto ctx = crossrt::VulkanContext::CreateDefault();
      if (hardwareOnly && !ctx->hasRayQuery)
        throw std::runtime_error("--hardware-only: " + ctx->DeviceName() + " has no ray queries");
      if (!hardwareOnly)
      {
        auto software = std::make_shared<PrimaryRays_Vulkan>(ctx, size, size);
        software->UseRayTracingHardware(false);
        runs.push_back({"PrimaryRays_Vulkan, " + bvh, software, {}});
        runs.back().renderer->SetScene(bvhScene, mesh.positions, mesh.indices);
      }
      if (ctx->hasRayQuery)
      {
        runs.push_back({"PrimaryRays_Vulkan, ray queries", std::make_shared<PrimaryRays_Vulkan>(ctx, size, size), {}});
        runs.back().renderer->SetScene(bvhScene, mesh.positions, mesh.indices);
      }
      else
        std::printf("%s has no ray queries: PrimaryRays_Vulkan traces with the translated traversal only\n", ctx->DeviceName().c_str());
    }
    catch (const std::exception& e)
    {
      std::fprintf(stderr, "primary_rays: Vulkan is not available, skipping PrimaryRays_Vulkan: %s\n", e.what());
    }
    for (Run& r : runs)
    {
      r.renderer->SetCamera(eye, centre, float3(0.0f, 1.0f, 0.0f), 40.0f);
      r.renderer->SetOcclusion(ao, radius * 0.3f);
      r.pixels.resize(size_t(size) * size);
      r.renderer->CommitDeviceData();
      r.renderer->Render(r.pixels.data());  // warm-up (uploads the scene)
      const auto t0 = std::chrono::steady_clock::now();
      r.renderer->Render(r.pixels.data());
      r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    }
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "primary_rays: %s\n", e.what());
    return 1;
  }

  const double rays = double(size) * size * (1 + ao);
  std::printf("primary rays + %d AO rays per hit, %dx%d, %zu triangles\n\n", ao, size, size, mesh.TriangleCount());
  std::printf("| %-32s | %9s | %15s | %24s |\n|%s|\n", "renderer", "ms", "Mrays/s (upper)", "pixels != original", std::string(92, '-').c_str());
  size_t worst = 0;
  for (Run& r : runs)
  {
    const size_t diff = DifferingPixels(r.pixels, runs[0].pixels);
    if (r.name.find("embree") == std::string::npos)
      worst = std::max(worst, diff);
    std::printf("| %-32s | %9.1f | %15.1f | %15zu (%5.2f%%) |\n", r.name.c_str(), r.ms, rays / r.ms * 1e-3, diff,
                100.0 * double(diff) / double(r.pixels.size()));
  }
  const uint32_t side = uint32_t(size);
  LiteImage::Image2D<uint32_t> image(side, side, runs.back().pixels.data());
  if (!LiteImage::SaveImage(outPath.c_str(), image))
    return 1;
  std::printf("\nwrote %s (from %s)\n", outPath.c_str(), runs.back().name.c_str());
  // Occlusion rays may fall on the other side of an edge where float rounding differs; more
  // than 0.5% of the pixels would mean a real difference.
  return double(worst) <= 0.005 * double(size) * size ? 0 : 1;
}
