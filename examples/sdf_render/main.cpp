// sdf_render: a mesh (or a built-in analytic scene) as a sparse voxel set of its signed distance,
// rendered by the original SdfRender and by SdfRender_CPU (all cores); the two images must be
// equal. Prints each one's rays per second and writes the image.
#include "MeshIO.h"
#include "SdfMesh.h"
#include "SdfRender.h"
#include "SdfRender_CPU.h"

#include "Image2D.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
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

double MedianMs(int repeats, SdfRender& r, uint32_t* pixels, float* depth)
{
  std::vector<double> ms;
  for (int i = 0; i < repeats; ++i)
  {
    const auto t0 = std::chrono::steady_clock::now();
    r.Render(pixels, depth);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

}  // namespace

int main(int argc, char** argv)
{
  std::string meshPath, outPath = "sdf_render.png";
  int size = 256, depth = 7, bytes = 2;
  int positional = 0;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h")
    {
      std::printf("usage: sdf_render [MESH | \"\"] [OUTPUT.png] [--size N] [--depth D] [--bytes 1|2|4]\n"
                  "  Builds a sparse voxel set of MESH's signed distance (\"\" or none: a built-in analytic scene) at 2^D\n"
                  "  voxels per axis, renders it with the original SdfRender and SdfRender_CPU (all cores), checks\n"
                  "  that the images are equal, prints rays per second and writes the image.\n");
      return 0;
    }
    if ((a == "--size" || a == "--depth" || a == "--bytes") && i + 1 < argc)
    {
      const int v = std::atoi(argv[++i]);
      (a == "--size" ? size : a == "--depth" ? depth : bytes) = v;
    }
    else if (positional == 0)
      meshPath = a, ++positional;
    else
      outPath = a, ++positional;
  }
  if (size < 1 || depth < 1 || depth > 10 || (bytes != 1 && bytes != 2 && bytes != 4))
  {
    std::fprintf(stderr, "sdf_render: --size must be positive, --depth 1..10, --bytes 1, 2 or 4\n");
    return 2;
  }

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

  litesdf::SdfBuildStats stats;
  const litesdf::SdfSVS svs = litesdf::BuildSVS(*field, float3(-1.0f, -1.0f, -1.0f), 2.0f, uint32_t(depth), uint32_t(bytes), &stats);
  std::printf("%s: %zu voxels at %d^3, %d bytes per value, %.2f MiB, built in %.0f ms\n", what.c_str(), svs.VoxelCount(), 1 << depth, bytes,
              double(svs.Bytes()) / 1048576.0, stats.milliseconds);

  SdfRender original(size, size);
  std::shared_ptr<SdfRender> cpu = CreateSdfRender_CPU(size, size);
  for (SdfRender* r : {&original, cpu.get()})
  {
    r->SetField(svs, 4);
    r->SetCamera(float3(1.2f, 0.9f, -2.6f), float3(0.0f, 0.0f, 0.0f), 40.0f);
    r->CommitDeviceData();
  }
  const size_t n = size_t(size) * size;
  std::vector<uint32_t> pixels(n), pixelsCpu(n);
  std::vector<float> depthOriginal(n), depthCpu(n);
  const double msOriginal = MedianMs(3, original, pixels.data(), depthOriginal.data());
  const double msCpu = MedianMs(3, *cpu, pixelsCpu.data(), depthCpu.data());
  const size_t hits = size_t(std::count_if(depthOriginal.begin(), depthOriginal.end(), [](float t) { return t >= 0.0f; }));
  std::printf("| %-22s | %9s | %8s |\n", "class", "ms", "Mrays/s");
  std::printf("| %-22s | %9.2f | %8.2f |\n", "SdfRender (original)", msOriginal, double(n) / (msOriginal * 1000.0));
  std::printf("| %-22s | %9.2f | %8.2f |  %.2fx the original\n", "SdfRender_CPU", msCpu, double(n) / (msCpu * 1000.0), msOriginal / msCpu);
  std::printf("%zu of %zu rays hit\n", hits, n);
  if (std::memcmp(pixels.data(), pixelsCpu.data(), n * sizeof(uint32_t)) != 0 || std::memcmp(depthOriginal.data(), depthCpu.data(), n * sizeof(float)) != 0)
  {
    std::fprintf(stderr, "sdf_render: SdfRender_CPU's image differs from the original's\n");
    return 1;
  }
  if (hits == 0)
  {
    std::fprintf(stderr, "sdf_render: no ray hit the field\n");
    return 1;
  }
  LiteImage::Image2D<uint32_t> image{uint32_t(size), uint32_t(size), pixels.data()};
  if (!LiteImage::SaveImage(outPath.c_str(), image))
  {
    std::fprintf(stderr, "sdf_render: cannot write %s\n", outPath.c_str());
    return 1;
  }
  std::printf("wrote %s\n", outPath.c_str());
  return 0;
}
