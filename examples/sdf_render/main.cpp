// sdf_render: a mesh (or a built-in analytic scene) as a dense grid, a sparse voxel set and a sparse
// brick set of its signed distance, each placed in a scene through ISceneObject and rendered with
// normals and ambient occlusion by the original SdfRender (on BVHScene, on Embree and on
// SdfLeafScene), SdfRender_CPU (all cores), SdfRender_Vulkan (the default device) and
// SdfRender_VulkanLeaves (SdfLeafScene, the paper's level-3 form: intersection shaders where the
// device has ray tracing pipelines, the switch over the representation elsewhere). Prints a table of
// times and of the pixels that differ from the original's, and writes one image per representation.
#include "MeshIO.h"
#include "SdfBVH.h"
#include "SdfMesh.h"
#include "SdfRender.h"
#include "SdfRender_CPU.h"
#include "SdfRender_Vulkan.h"
#include "SdfRender_VulkanLeaves.h"
#include "SdfLeafScene.h"

#include "Image2D.h"

#include "CommandLine.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace {

// The built-in scene: a torus, a rounded box and a sphere, united.
class Union : public litesdf::ISdf
{
public:
  float Distance(float3 p) const override { return std::min(m_torus.Distance(p), std::min(m_box.Distance(p), m_sphere.Distance(p))); }

private:
  litesdf::SdfTorus m_torus{float3(0.0f, -0.35f, 0.0f), 0.55f, 0.15f};
  litesdf::SdfRoundedBox m_box{float3(-0.3f, 0.3f, 0.2f), float3(0.25f, 0.25f, 0.25f), 0.06f};
  litesdf::SdfSphere m_sphere{float3(0.35f, 0.3f, -0.1f), 0.3f};
};

struct Run
{
  std::string name;
  std::shared_ptr<SdfRender> renderer;
  bool mustEqual;  // bit for bit the original's image (the same code on the CPU)
  std::vector<uint32_t> pixels;
  std::vector<float> depth;
  double ms = 0.0;
};

size_t DifferingPixels(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b)
{
  size_t n = 0;
  for (size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 24; c += 8)
      if (std::abs(int((a[i] >> c) & 0xFF) - int((b[i] >> c) & 0xFF)) > 2)
      {
        ++n;
        break;
      }
  return n;
}

std::string WithSuffix(const std::string& path, const std::string& suffix)
{
  const size_t dot = path.rfind('.');
  return dot == std::string::npos || path.find('/', dot) != std::string::npos ? path + suffix : path.substr(0, dot) + suffix + path.substr(dot);
}

// The field's representations over [-1, 1]^3 at 2^depth voxels per axis.
struct Representation
{
  std::string name;
  std::string detail;
  size_t bytes;
  std::function<uint32_t(ISceneObject&)> add;
};

}  // namespace

int main(int argc, char** argv)
{
  std::string meshPath, outPath = "sdf_render.png";
  int size = 256, depth = 7, bytes = 2, ao = 4;
  bool hardwareOnly = false;
  crossrt::CommandLine app("sdf_render",
                           "Builds a dense grid, a sparse voxel set and a sparse brick set (bricks of 4^3) of MESH's signed\n"
                           "distance (\"\" or none: a built-in analytic scene) at 2^D voxels per axis, renders each with normals\n"
                           "and ambient occlusion by the original SdfRender (BVHScene and Embree), SdfRender_CPU (all cores)\n"
                           "and SdfRender_Vulkan, checks that their images agree, and writes OUTPUT-grid.png, -svs.png, -sbs.png.");
  app.add_option("MESH", meshPath, "the mesh (\"\": the built-in scene)");
  app.add_option("OUTPUT.png", outPath, "the images' name");
  app.add_option("--size", size, "width and height in pixels")->check(crossrt::Positive());
  app.add_option("--depth", depth, "2^D voxels per axis")->check(CLI::Range(2, 10));
  app.add_option("--bytes", bytes, "bytes per distance")->check(CLI::IsMember({1, 2, 4}));
  app.add_option("--ao", ao, "ambient occlusion rays per pixel")->check(CLI::Range(0, 16));
  app.add_flag("--hardware-only", hardwareOnly,
               "on Vulkan only the intersection shaders of the ray tracing pipeline (which the device must have), not the\n"
               "translated traversal nor its level-3 switch");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;

  std::unique_ptr<litesdf::ISdf> field;
  std::string what = "the built-in scene";
  if (!meshPath.empty())
  {
    TriangleMesh tm;
    try
    {
      tm = LoadMesh(meshPath);
    }
    catch (const std::exception& e)
    {
      std::fprintf(stderr, "sdf_render: %s\n", e.what());
      return 1;
    }
    field = std::make_unique<litesdf::SdfMesh>(litesdf::FitIntoCube(tm.positions, 0.9f), tm.indices);  // the field covers [-1, 1]^3
    what = meshPath + " (" + std::to_string(tm.TriangleCount()) + " triangles)";
  }
  else
    field = std::make_unique<Union>();

  const float3 boxMin(-1.0f, -1.0f, -1.0f);
  const auto t0 = std::chrono::steady_clock::now();
  const litesdf::SdfGrid grid = litesdf::BuildGrid(*field, boxMin, 2.0f, (1u << depth) + 1);
  const litesdf::SdfSVS svs = litesdf::BuildSVS(*field, boxMin, 2.0f, uint32_t(depth), uint32_t(bytes));
  const litesdf::SdfSBS sbs = litesdf::BuildSBS(*field, boxMin, 2.0f, uint32_t(depth), 4, uint32_t(bytes));
  const double buildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%s at %d^3 voxels, %d bytes per value (the grid: floats), built in %.0f ms\n", what.c_str(), 1 << depth, bytes, buildMs);
  const std::vector<Representation> representations = {
      {"grid", std::to_string(grid.samples) + "^3 samples", grid.Bytes(), [&](ISceneObject& s) { return s.AddGeom_SdfGrid(grid); }},
      {"svs", std::to_string(svs.VoxelCount()) + " voxels", svs.Bytes(), [&](ISceneObject& s) { return s.AddGeom_SdfSVS(svs); }},
      {"sbs", std::to_string(sbs.BrickCount()) + " bricks", sbs.Bytes(), [&](ISceneObject& s) { return s.AddGeom_SdfSBS(sbs); }},
  };

  std::shared_ptr<crossrt::VulkanContext> ctx;
  try
  {
    ctx = crossrt::VulkanContext::CreateDefault();
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "sdf_render: Vulkan is not available, skipping SdfRender_Vulkan: %s\n", e.what());
  }

  const size_t n = size_t(size) * size;
  const double rays = double(n) * (1 + ao);
  bool failed = false;
  for (const Representation& rep : representations)
  {
    std::vector<Run> runs;
    try
    {
      auto sceneOf = [&](const char* impl) {
        auto scene = MakeSceneRT(impl);
        scene->AddInstance(rep.add(*scene), LiteMath::float4x4());
        scene->CommitScene();
        return scene;
      };
      auto bvh = sceneOf("sah");
      runs.push_back({"original, BVHScene (1 thread)", std::make_shared<SdfRender>(size, size), true, {}, {}});
      runs.back().renderer->SetScene(bvh);
      runs.push_back({"original, Embree (1 thread)", std::make_shared<SdfRender>(size, size), false, {}, {}});
      runs.back().renderer->SetScene(sceneOf("embree"));
      runs.push_back({"SdfRender_CPU", CreateSdfRender_CPU(size, size), true, {}, {}});
      runs.back().renderer->SetScene(bvh);
      auto leaves = std::make_shared<SdfLeafScene>();  // the paper's level-3 form
      leaves->AddInstance(rep.add(*leaves), LiteMath::float4x4());
      leaves->CommitScene();
      runs.push_back({"original, SdfLeafScene (1 thread)", std::make_shared<SdfRender>(size, size), false, {}, {}});
      runs.back().renderer->SetScene(leaves);
      if (ctx)
      {
        // The translated traversal, SDF leaves included. (Ray queries take triangles only: a field
        // would need procedural boxes and an intersection in the shader.)
        if (hardwareOnly && !ctx->hasRayTracingPipeline)
          throw std::runtime_error("--hardware-only: " + ctx->DeviceName() + " has no ray tracing pipelines");
        for (bool hardware : {true, false})
        {
          if ((hardware && !ctx->hasRayTracingPipeline) || (!hardware && hardwareOnly))
            continue;
          auto level3 = std::make_shared<SdfRender_VulkanLeaves>(ctx, size, size);
          level3->UseRayTracingPipelines(hardware);
          runs.push_back({hardware ? "VulkanLeaves, intersection shd." : "VulkanLeaves, switch", level3, false, {}, {}});
          runs.back().renderer->SetScene(leaves);
        }
        if (!hardwareOnly)
        {
          auto vulkan = std::make_shared<SdfRender_Vulkan>(ctx, size, size);
          vulkan->UseRayTracingHardware(false);
          runs.push_back({"SdfRender_Vulkan", vulkan, false, {}, {}});
          runs.back().renderer->SetScene(bvh);
        }
      }
      for (Run& r : runs)
      {
        r.renderer->SetCamera(float3(1.2f, 0.9f, -2.6f), float3(0.0f, 0.0f, 0.0f), 40.0f);
        r.renderer->SetOcclusion(ao, 0.3f);
        r.renderer->CommitDeviceData();
        r.pixels.resize(n);
        r.depth.resize(n);
        r.renderer->Render(r.pixels.data(), r.depth.data());  // warm-up (uploads the scene)
        const auto start = std::chrono::steady_clock::now();
        r.renderer->Render(r.pixels.data(), r.depth.data());
        r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      }
    }
    catch (const std::exception& e)
    {
      std::fprintf(stderr, "sdf_render: %s\n", e.what());
      return 1;
    }
    const size_t hits = size_t(std::count_if(runs[0].depth.begin(), runs[0].depth.end(), [](float t) { return t >= 0.0f; }));
    std::printf("\n%s: %s, %.2f MiB; %zu of %zu camera rays hit, %d AO rays per hit\n", rep.name.c_str(), rep.detail.c_str(),
                double(rep.bytes) / 1048576.0, hits, n, ao);
    std::printf("| %-33s | %9s | %15s | %22s |\n", "renderer", "ms", "Mrays/s (upper)", "pixels != original");
    for (const Run& r : runs)
    {
      const size_t diff = DifferingPixels(r.pixels, runs[0].pixels);
      std::printf("| %-33s | %9.1f | %15.2f | %13zu (%5.2f%%) |\n", r.name.c_str(), r.ms, rays / r.ms * 1e-3, diff, 100.0 * double(diff) / double(n));
      const bool equal = std::memcmp(r.pixels.data(), runs[0].pixels.data(), n * sizeof(uint32_t)) == 0 &&
                         std::memcmp(r.depth.data(), runs[0].depth.data(), n * sizeof(float)) == 0;
      // The same code on the CPU gives the same bits; Embree and the GPU round differently, where a
      // ray grazes a voxel or an occlusion ray a surface: at most 1% of the pixels.
      if ((r.mustEqual && !equal) || 100 * diff > n)
      {
        std::fprintf(stderr, "sdf_render: %s's %s image differs from the original's\n", r.name.c_str(), rep.name.c_str());
        failed = true;
      }
    }
    if (hits == 0)
    {
      std::fprintf(stderr, "sdf_render: no ray hit the %s\n", rep.name.c_str());
      failed = true;
    }
    const std::string path = WithSuffix(outPath, "-" + rep.name);
    LiteImage::Image2D<uint32_t> image{uint32_t(size), uint32_t(size), runs.back().pixels.data()};
    if (!LiteImage::SaveImage(path.c_str(), image))
    {
      std::fprintf(stderr, "sdf_render: cannot write %s\n", path.c_str());
      return 1;
    }
    std::printf("wrote %s (from %s)\n", path.c_str(), runs.back().name.c_str());
  }
  return failed ? 1 : 0;
}
