// bench_sdf: signed distance fields, speed against accuracy (a program that prints tables).
//
// For each mesh, scaled into [-1, 1]^3: the exact signed distance (SdfMesh) is sampled into a dense
// grid, sparse voxel sets and sparse brick sets over a sweep of their knobs (depth, bytes per value,
// brick size, Newton iterations). The same camera rays are traced through each, and through OpenVDB's
// level set of the same mesh (meshToLevelSet + LevelSetRayIntersector) as the peer, single-threaded
// alike. The reference is the exact mesh distance, sphere-traced to 1e-5.
// Per row: build ms, bytes (data, and with the BVH), Mrays/s on one thread (litesdf's own traversal),
// the mean and maximum distance of hit points from the mesh surface, hit agreement, and the PSNR of
// depth and normal images against the reference. Then the same field placed in a scene through
// ISceneObject (BVHScene, 4 Newton iterations) and the same camera rays traced by the translated
// SdfRender_CPU (all cores) and SdfRender_Vulkan (the default device); OpenVDB's intersector on all
// cores too, one copy per thread. Writes out/bench_sdf.csv; bench/plot_sdf.py plots error against time.
// First, per mesh, the paper's Figure 9: render time against model size for SBS at growing depths,
// on the GPU, software against hardware: SdfRender_Vulkan on BVHScene, and SdfRender_VulkanLeaves on
// SdfLeafScene (the paper's level-3 form) with its switch over the representation and, where the
// device has ray tracing pipelines, with intersection shaders. Writes out/bench_sdf_fig9.csv. Then
// Figure 10: those SdfLeafScene frames split into the walk and the bricks' intersection, from frames
// with each brick solved once and three times (out/bench_sdf_fig10.csv).
//
//   bench_sdf [--size N] [--figures] [MESH...]   (default: bunny, armadillo and dragon from build/data/meshes)
#include "BenchSupport.h"
#include "MeshIO.h"
#include "SdfBVH.h"
#include "SdfMesh.h"
#include "SdfRender.h"
#include "SdfRender_CPU.h"
#include "SdfRender_Vulkan.h"
#include "SdfRender_VulkanLeaves.h"
#include "SdfLeafScene.h"
#include "SdfTrace.h"
#include "CommandLine.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/RayIntersector.h>

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

using namespace litesdf;
using LiteMath::float3;

namespace {

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

struct Camera {
  int size;
  float3 eye, forward, right, up;
  void Ray(int x, int y, float3& origin, float3& dir) const {
    const float u = (float(x) + 0.5f) / float(size) * 2.0f - 1.0f, v = 1.0f - (float(y) + 0.5f) / float(size) * 2.0f;
    origin = eye;
    dir = LiteMath::normalize(forward + 0.45f * (u * right + v * up));
  }
};

// One traced image: depth (t, -1 for a miss) and normal per pixel.
struct Image {
  std::vector<float> t;
  std::vector<float3> normal;
};

struct Row {
  std::string mesh, representation, knobs;
  double buildMs = 0, dataBytes = 0, totalBytes = 0, mraysPerS = 0;
  double mraysCpu = 0, mraysVulkan = 0;  // all cores (SdfRender_CPU, or OpenVDB with OpenMP), and SdfRender_Vulkan; 0: not run
  double meanError = 0, maxError = 0, hitAgreement = 0, depthPsnr = 0, normalPsnr = 0;
};

// Compares an image with the reference: surface error of hits (exact mesh distance at the hit
// point), agreement of hit masks, and PSNR of depth (over the scene's depth range) and normals.
void Score(const Image& image, const Image& ref, const Camera& cam, const SdfMesh& mesh, Row& row) {
  double sumError = 0, maxError = 0, depthSe = 0, normalSe = 0;
  size_t hits = 0, agree = 0, n = image.t.size();
  for (size_t i = 0; i < n; ++i) {
    const bool h = image.t[i] >= 0.0f, r = ref.t[i] >= 0.0f;
    agree += h == r;
    const float depth = h ? image.t[i] / 6.0f : 1.0f, refDepth = r ? ref.t[i] / 6.0f : 1.0f;
    depthSe += double(depth - refDepth) * (depth - refDepth);
    const float3 nn = h ? 0.5f * (image.normal[i] + float3(1.0f, 1.0f, 1.0f)) : float3(0.0f, 0.0f, 0.0f);
    const float3 rn = r ? 0.5f * (ref.normal[i] + float3(1.0f, 1.0f, 1.0f)) : float3(0.0f, 0.0f, 0.0f);
    const float3 d = nn - rn;
    normalSe += LiteMath::dot(d, d) / 3.0;
    if (!h) continue;
    float3 origin, dir;
    cam.Ray(int(i % cam.size), int(i / cam.size), origin, dir);
    const double e = mesh.UnsignedDistance(origin + image.t[i] * dir);
    sumError += e;
    maxError = std::max(maxError, e);
    ++hits;
  }
  row.meanError = hits ? sumError / double(hits) : 0.0;
  row.maxError = maxError;
  row.hitAgreement = double(agree) / double(n);
  row.depthPsnr = 10.0 * std::log10(1.0 / std::max(depthSe / double(n), 1e-12));
  row.normalPsnr = 10.0 * std::log10(1.0 / std::max(normalSe / double(n), 1e-12));
}

// Traces every pixel with `trace` (returns t and the normal); the median of 3 timed runs.
Image TraceImage(const Camera& cam, const std::function<SdfHit(float3, float3)>& trace, double& mraysPerS) {
  Image image;
  image.t.resize(size_t(cam.size) * cam.size);
  image.normal.resize(image.t.size());
  const double ms = MedianMs(2, [&] {
    for (int y = 0; y < cam.size; ++y)
      for (int x = 0; x < cam.size; ++x) {
        float3 origin, dir;
        cam.Ray(x, y, origin, dir);
        const SdfHit h = trace(origin, dir);
        image.t[size_t(y) * cam.size + x] = h.t;
        image.normal[size_t(y) * cam.size + x] = h.normal;
      }
  });
  mraysPerS = double(image.t.size()) / (ms * 1000.0);
  return image;
}

float3 MeshNormal(const SdfMesh& mesh, float3 p) {
  const float e = 1e-4f;
  return LiteMath::normalize(float3(mesh.Distance(p + float3(e, 0, 0)) - mesh.Distance(p - float3(e, 0, 0)),
                                    mesh.Distance(p + float3(0, e, 0)) - mesh.Distance(p - float3(0, e, 0)),
                                    mesh.Distance(p + float3(0, 0, e)) - mesh.Distance(p - float3(0, 0, e))));
}

void Print(const Row& r) {
  std::printf("| %-10s | %-26s | %9.0f | %9.2f | %9.2f | %8.3f | %8.3f | %8.3f | %9.5f | %9.5f | %6.2f%% | %6.1f | %6.1f |\n",
              r.representation.c_str(), r.knobs.c_str(), r.buildMs, r.dataBytes / 1048576.0, r.totalBytes / 1048576.0, r.mraysPerS,
              r.mraysCpu, r.mraysVulkan, r.meanError, r.maxError, 100.0 * r.hitAgreement, r.depthPsnr, r.normalPsnr);
  std::fflush(stdout);
}

// The translated renderers, made once per run (a Vulkan class compiles its pipelines when made) and
// given each field's scene in turn.
struct Translated {
  std::shared_ptr<SdfRender> cpu, vulkan;
  std::shared_ptr<SdfRender_VulkanLeaves> leaves;  // on SdfLeafScene: the switch, or intersection shaders
  bool hardware = false;                           // the device has ray tracing pipelines
  int size = 0;
  std::vector<uint32_t> pixels;
  std::vector<float> depth;
};

double RenderMrays(SdfRender& r, Translated& tr, std::shared_ptr<ISceneObject> scene) {
  r.SetScene(std::move(scene));
  r.CommitDeviceData();
  r.Render(tr.pixels.data(), tr.depth.data());  // uploads the scene
  const double ms = MedianMs(3, [&] { r.Render(tr.pixels.data(), tr.depth.data()); });
  return double(tr.size) * tr.size / (ms * 1000.0);
}

// Places `add`'s field in a BVHScene and times SdfRender_CPU and SdfRender_Vulkan on it.
void TimeTranslated(Translated& tr, const std::function<uint32_t(ISceneObject&)>& add, Row& row) {
  auto scene = MakeSceneRT("sah");
  scene->AddInstance(add(*scene), LiteMath::float4x4());
  scene->CommitScene();
  row.mraysCpu = RenderMrays(*tr.cpu, tr, scene);
  if (tr.vulkan) row.mraysVulkan = RenderMrays(*tr.vulkan, tr, scene);
}

// Frame times of one field: `ms` per frame, the median of rounds that alternate the settings.
struct SplitMs {
  double walk = 0, intersection = 0;  // ms per frame: the traversal (with its shader calls), the bricks' solves
};

// The paper's Figure 10 for one SdfLeafScene, traced by `r`: frames with each brick solved once and
// three times (SdfLeafScene::m_intersectRepeats) take walk + k * intersection, so their difference
// halved is the intersection's share. Rounds alternate k = 1 and 3; medians of 5.
SplitMs SplitFrame(SdfRender& r, Translated& tr, const std::shared_ptr<SdfLeafScene>& scene) {
  std::vector<double> once, thrice;
  for (int round = 0; round < 5; ++round)
    for (uint32_t k : {1u, 3u}) {
      scene->m_intersectRepeats = k;
      (k == 1 ? once : thrice).push_back(double(tr.size) * tr.size / 1000.0 / RenderMrays(r, tr, scene));
    }
  scene->m_intersectRepeats = 1;
  SplitMs split;
  split.intersection = std::max(0.0, (MedianOf(thrice) - MedianOf(once)) / 2.0);
  split.walk = MedianOf(once) - split.intersection;
  return split;
}

// The paper's Figures 9 and 10 on the GPU for one mesh, over SBSs of growing depth (brick 4, 1 B):
// render time against model size, software against hardware, and the frame split into the walk and
// the bricks' intersection.
void GpuFigures(Translated& tr, const SdfMesh& mesh, const std::string& name, std::ofstream& fig9, std::ofstream& fig10) {
  const float3 boxMin(-1.0f, -1.0f, -1.0f);
  const int size = tr.size;
  std::printf("\n%s, the paper's Figure 9: ms per %dx%d frame on the GPU against the SBS's size (brick 4, 1 B; SdfLeafScene holds it as floats)\n", name.c_str(), size, size);
  std::printf("| %-8s | %9s | %18s | %22s | %26s |\n", "SBS", "MiB", "BVHScene (compute)", "SdfLeafScene, switch", "SdfLeafScene, intersection");
  struct Split {
    uint32_t depth;
    double mib;
    SplitMs software, hardware;
  };
  std::vector<Split> splits;
  for (uint32_t depth : {5u, 6u, 7u}) {
    const SdfSBS sbs = BuildSBS(mesh, boxMin, 2.0f, depth, 4, 1);
    auto bvhScene = MakeSceneRT("sah");
    bvhScene->AddInstance(bvhScene->AddGeom_SdfSBS(sbs), LiteMath::float4x4());
    bvhScene->CommitScene();
    auto leafScene = std::make_shared<SdfLeafScene>();
    leafScene->AddInstance(leafScene->AddGeom_SdfSBS(sbs), LiteMath::float4x4());
    leafScene->CommitScene();
    const double rays = double(size) * size / 1000.0;  // per ms, in Mrays/s
    const double bvhMs = rays / RenderMrays(*tr.vulkan, tr, bvhScene);
    tr.leaves->UseRayTracingPipelines(false);
    const double switchMs = rays / RenderMrays(*tr.leaves, tr, leafScene);
    Split split{depth, double(sbs.Bytes()) / 1048576.0, SplitFrame(*tr.leaves, tr, leafScene), {}};
    double hardwareMs = 0.0;
    if (tr.hardware) {
      tr.leaves->UseRayTracingPipelines(true);
      hardwareMs = rays / RenderMrays(*tr.leaves, tr, leafScene);
      split.hardware = SplitFrame(*tr.leaves, tr, leafScene);
    }
    const std::string hw = tr.hardware ? std::to_string(hardwareMs).substr(0, 7) : "no RT pipelines";
    std::printf("| %5u^3  | %9.2f | %18.2f | %22.2f | %26s |\n", 1u << depth, split.mib, bvhMs, switchMs, hw.c_str());
    std::fflush(stdout);
    fig9 << name << "," << depth << "," << sbs.Bytes() << "," << bvhMs << "," << switchMs << "," << hardwareMs << "\n";
    splits.push_back(split);
  }
  std::printf("\n%s, the paper's Figure 10: the same frames split into the walk and the bricks' intersection, ms per frame\n"
              "(each brick solved once and three times, alternating, medians of 5: intersection = the difference / 2;\n"
              "the walk includes the intersection shaders' calls)\n", name.c_str());
  std::printf("| %-8s | %14s | %14s | %14s | %14s | %10s | %10s |\n", "SBS", "switch: walk", "intersection", "shaders: walk", "intersection",
              "walk HW/SW", "isect HW/SW");
  for (const Split& s : splits) {
    auto ratio = [](double hw, double sw) { return hw > 0.0 && sw > 0.0 ? hw / sw : 0.0; };
    std::printf("| %5u^3  | %14.2f | %14.2f | %14.2f | %14.2f | %9.2fx | %9.2fx |\n", 1u << s.depth, s.software.walk, s.software.intersection,
                s.hardware.walk, s.hardware.intersection, ratio(s.hardware.walk, s.software.walk),
                ratio(s.hardware.intersection, s.software.intersection));
    fig10 << name << "," << s.depth << "," << s.mib << "," << s.software.walk << "," << s.software.intersection << "," << s.hardware.walk << ","
          << s.hardware.intersection << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  int size = 160;
  std::vector<std::string> meshes;
  crossrt::CommandLine app("bench_sdf",
                           "SDF grid, sparse voxel and brick sets against OpenVDB: build time, bytes, Mrays/s (one thread),\n"
                           "surface error and image PSNR against the exact mesh distance. Writes out/bench_sdf.csv. On the GPU,\n"
                           "the paper's Figures 9 and 10: software against hardware over the SBS's size, and the frame split\n"
                           "into traversal and intersection (out/bench_sdf_fig9.csv, out/bench_sdf_fig10.csv).");
  app.add_option("MESH", meshes, "meshes (default: bunny, armadillo and dragon from build/data/meshes, scripts/fetch-meshes.sh)");
  app.add_option("--size", size, "width and height of the images in pixels")->check(crossrt::Positive());
  bool figuresOnly = false;
  app.add_flag("--figures", figuresOnly, "only the GPU's tables (the paper's Figures 9 and 10), not the representations' sweep");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  if (meshes.empty())
    for (const char* name : {"bunny00.off", "armadillo.off", "dragon_vrip_res2.ply.gz"})
      if (std::filesystem::exists(std::string("build/data/meshes/") + name)) meshes.push_back(std::string("build/data/meshes/") + name);
  if (meshes.empty()) {
    std::cerr << "bench_sdf: no meshes: run scripts/fetch-meshes.sh, or name mesh files\n";
    return 1;
  }
  openvdb::initialize();
  Translated translated;
  translated.size = size;
  translated.pixels.resize(size_t(size) * size);
  translated.depth.resize(size_t(size) * size);
  translated.cpu = CreateSdfRender_CPU(size, size);
  try {
    auto ctx = crossrt::VulkanContext::CreateDefault();
    auto vulkan = std::make_shared<SdfRender_Vulkan>(ctx, size, size);
    vulkan->UseRayTracingHardware(false);  // ray queries take triangles only
    translated.vulkan = vulkan;
    translated.leaves = std::make_shared<SdfRender_VulkanLeaves>(ctx, size, size);
    translated.hardware = ctx->hasRayTracingPipeline;
    std::printf("bench_sdf: the GPU is %s (%s ray tracing pipelines); the CPU is %s\n", ctx->DeviceName().c_str(),
                translated.hardware ? "with" : "without", CpuModel().c_str());
  } catch (const std::exception& e) {
    std::cerr << "bench_sdf: Vulkan is not available, no SdfRender_Vulkan column: " << e.what() << "\n";
  }
  const float fovY = 2.0f * std::atan(0.45f) * 180.0f / 3.14159265f;  // Camera's
  for (SdfRender* r : {translated.cpu.get(), translated.vulkan.get(), static_cast<SdfRender*>(translated.leaves.get())})
    if (r) {
      r->SetCamera(float3(1.2f, 0.9f, -2.6f), float3(0.0f, 0.0f, 0.0f), fovY);
      r->SetOcclusion(0, 0.0f);
    }
  std::filesystem::create_directories("out");
  std::ofstream csv("out/bench_sdf.csv");
  csv << "mesh,representation,knobs,build_ms,data_bytes,total_bytes,mrays_per_s,mrays_per_s_cpu,mrays_per_s_vulkan,mean_error,max_error,hit_agreement,depth_psnr,normal_psnr\n";
  std::ofstream fig9("out/bench_sdf_fig9.csv");
  fig9 << "mesh,depth,sbs_bytes,bvhscene_ms,leaves_switch_ms,leaves_hardware_ms\n";
  std::ofstream fig10("out/bench_sdf_fig10.csv");
  fig10 << "mesh,depth,sbs_mib,switch_walk_ms,switch_intersection_ms,shaders_walk_ms,shaders_intersection_ms\n";

  for (const std::string& path : meshes) {
    TriangleMesh tm;
    try {
      tm = LoadMesh(path);
    } catch (const std::exception& e) {
      std::cerr << "bench_sdf: " << e.what() << "\n";
      return 1;
    }
    const std::vector<float3> vertices = FitIntoCube(tm.positions, 0.9f);  // the fields cover [-1, 1]^3
    const SdfMesh mesh(vertices, tm.indices);
    const std::string name = std::filesystem::path(path).filename().string();
    const Camera cam{size, float3(1.2f, 0.9f, -2.6f), LiteMath::normalize(float3(-1.2f, -0.9f, 2.6f)),
                     LiteMath::normalize(LiteMath::cross(float3(0, 1, 0), float3(-1.2f, -0.9f, 2.6f))), float3(0, 0, 0)};
    Camera camera = cam;
    camera.up = LiteMath::cross(camera.forward, camera.right);
    if (translated.vulkan)
      GpuFigures(translated, mesh, name, fig9, fig10);
    if (figuresOnly)
      continue;

    // The reference: the exact distance, sphere-traced.
    double refRate = 0;
    const Image ref = TraceImage(camera, [&](float3 o, float3 d) {
      SdfHit h;
      h.t = SphereTrace(mesh, o, d, 0.0f, 6.0f, 1e-5f, 512);
      h.normal = h.t >= 0.0f ? MeshNormal(mesh, o + h.t * d) : float3(0, 0, 0);
      return h;
    }, refRate);
    std::printf("\n%s: %zu triangles, %dx%d rays; errors in units of the mesh's extent / 1.8 (the box is 2 wide). Mrays/s: 1 thread,\n"
                "the field in a BVHScene through SdfRender_CPU (all %d cores; OpenVDB: one intersector per thread) and SdfRender_Vulkan.\n"
                "Sign: %s (%zu edges not shared by exactly two triangles)\n\n",
                name.c_str(), mesh.TriangleCount(), size, size, omp_get_max_threads(),
                mesh.Sign() == SdfSign::WindingNumber ? "the fast winding number" : "angle-weighted pseudo-normals", mesh.OpenOrNonManifoldEdges());
    std::printf("| %-10s | %-26s | %9s | %9s | %9s | %8s | %8s | %8s | %9s | %9s | %7s | %6s | %6s |\n", "kind", "knobs", "build ms", "data MiB",
                "+BVH MiB", "1 thread", "_CPU", "_Vulkan", "mean err", "max err", "hits", "dPSNR", "nPSNR");
    std::printf("|%s|\n", std::string(172, '-').c_str());
    auto emit = [&](Row& row, const Image& image) {
      row.mesh = name;
      Score(image, ref, camera, mesh, row);
      Print(row);
      csv << row.mesh << "," << row.representation << ",\"" << row.knobs << "\"," << row.buildMs << "," << row.dataBytes << ","
          << row.totalBytes << "," << row.mraysPerS << "," << row.mraysCpu << "," << row.mraysVulkan << "," << row.meanError << "," << row.maxError << "," << row.hitAgreement << ","
          << row.depthPsnr << "," << row.normalPsnr << "\n";
    };
    const float3 boxMin(-1.0f, -1.0f, -1.0f);

    {  // The dense grid, sphere-traced; normals by central differences of the interpolant.
      Row row;
      row.representation = "grid";
      row.knobs = "64^3 samples";
      const auto t0 = std::chrono::steady_clock::now();
      const SdfGrid grid = BuildGrid(mesh, boxMin, 2.0f, 64);
      row.buildMs = MsSince(t0);
      row.dataBytes = row.totalBytes = double(grid.Bytes());
      const Image image = TraceImage(camera, [&](float3 o, float3 d) {
        SdfHit h;
        h.t = SphereTraceGrid(grid, o, d, 0.0f, 6.0f, 1e-4f, 512);
        const float e = 0.5f * grid.CellSize();
        const float3 p = o + h.t * d;
        h.normal = h.t < 0.0f ? float3(0, 0, 0)
                              : LiteMath::normalize(float3(grid.Sample(p + float3(e, 0, 0)) - grid.Sample(p - float3(e, 0, 0)),
                                                           grid.Sample(p + float3(0, e, 0)) - grid.Sample(p - float3(0, e, 0)),
                                                           grid.Sample(p + float3(0, 0, e)) - grid.Sample(p - float3(0, 0, e))));
        return h;
      }, row.mraysPerS);
      TimeTranslated(translated, [&](ISceneObject& scene) { return scene.AddGeom_SdfGrid(grid); }, row);
      emit(row, image);
    }
    for (uint32_t depth : {5u, 6u, 7u})
      for (uint32_t bytes : {1u, 2u}) {
        Row row;
        row.representation = "SVS";
        row.knobs = std::to_string(1u << depth) + "^3, " + std::to_string(bytes) + " B, 4 Newton";
        SdfBuildStats stats;
        const auto t0 = std::chrono::steady_clock::now();
        const SdfSVS svs = BuildSVS(mesh, boxMin, 2.0f, depth, bytes, &stats);
        const BVHTree bvh = BuildSdfBVH(svs);
        row.buildMs = MsSince(t0);
        row.dataBytes = double(svs.Bytes());
        row.totalBytes = row.dataBytes + double(bvh.nodes.size() * sizeof(BVHNode) + bvh.primIndices.size() * 4);
        const Image image = TraceImage(camera, [&](float3 o, float3 d) { return TraceSVS(svs, bvh, o, d, 0.0f, 6.0f, 4); }, row.mraysPerS);
        TimeTranslated(translated, [&](ISceneObject& scene) { return scene.AddGeom_SdfSVS(svs); }, row);
        emit(row, image);
      }
    {  // Newton iterations: the knob at 128^3, 2 bytes.
      const SdfSVS svs = BuildSVS(mesh, boxMin, 2.0f, 7, 2);
      const BVHTree bvh = BuildSdfBVH(svs);
      for (int iterations : {1, 2, 8}) {
        Row row;
        row.representation = "SVS";
        row.knobs = "128^3, 2 B, " + std::to_string(iterations) + " Newton";
        row.dataBytes = double(svs.Bytes());
        row.totalBytes = row.dataBytes + double(bvh.nodes.size() * sizeof(BVHNode) + bvh.primIndices.size() * 4);
        const Image image = TraceImage(camera, [&](float3 o, float3 d) { return TraceSVS(svs, bvh, o, d, 0.0f, 6.0f, iterations); },
                                       row.mraysPerS);
        emit(row, image);
      }
    }
    for (uint32_t depth : {6u, 7u})
      for (uint32_t brick : {4u, 8u}) {
        Row row;
        row.representation = "SBS";
        row.knobs = std::to_string(1u << depth) + "^3, brick " + std::to_string(brick) + ", 1 B";
        const auto t0 = std::chrono::steady_clock::now();
        const SdfSBS sbs = BuildSBS(mesh, boxMin, 2.0f, depth, brick, 1);
        const BVHTree bvh = BuildSdfBVH(sbs);
        row.buildMs = MsSince(t0);
        row.dataBytes = double(sbs.Bytes());
        row.totalBytes = row.dataBytes + double(bvh.nodes.size() * sizeof(BVHNode) + bvh.primIndices.size() * 4);
        const Image image = TraceImage(camera, [&](float3 o, float3 d) { return TraceSBS(sbs, bvh, o, d, 0.0f, 6.0f, 4); }, row.mraysPerS);
        TimeTranslated(translated, [&](ISceneObject& scene) { return scene.AddGeom_SdfSBS(sbs); }, row);
        emit(row, image);
      }
    // The peer: OpenVDB's narrow-band level set of the same mesh, at the same voxel sizes.
    for (uint32_t depth : {6u, 7u}) {
      Row row;
      row.representation = "OpenVDB";
      row.knobs = std::to_string(1u << depth) + "^3 voxels, band 3";
      std::vector<openvdb::Vec3s> points(vertices.size());
      for (size_t v = 0; v < vertices.size(); ++v) points[v] = openvdb::Vec3s(vertices[v].x, vertices[v].y, vertices[v].z);
      std::vector<openvdb::Vec3I> triangles(mesh.TriangleCount());
      for (size_t t = 0; t < triangles.size(); ++t)
        triangles[t] = openvdb::Vec3I(tm.indices[3 * t], tm.indices[3 * t + 1], tm.indices[3 * t + 2]);
      const auto t0 = std::chrono::steady_clock::now();
      auto transform = openvdb::math::Transform::createLinearTransform(2.0 / double(1u << depth));
      openvdb::FloatGrid::Ptr grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*transform, points, triangles, 3.0f);
      row.buildMs = MsSince(t0);
      row.dataBytes = row.totalBytes = double(grid->memUsage());
      using Intersector = openvdb::tools::LevelSetRayIntersector<openvdb::FloatGrid>;
      auto trace = [&](const Intersector& intersector, float3 o, float3 d) {
        SdfHit h = Missed();
        openvdb::math::Ray<double> ray(openvdb::Vec3d(o.x, o.y, o.z), openvdb::Vec3d(d.x, d.y, d.z), 0.0, 6.0);
        openvdb::Vec3d p, n;
        double t = 0;
        if (intersector.intersectsWS(ray, p, n, t)) {
          h.t = float(t);
          n.normalize();
          h.normal = float3(float(n[0]), float(n[1]), float(n[2]));
        }
        return h;
      };
      const Intersector intersector(*grid);
      const Image image = TraceImage(camera, [&](float3 o, float3 d) { return trace(intersector, o, d); }, row.mraysPerS);
      // All cores: rows over the threads, an intersector each (they are not thread-safe).
      std::vector<float> allCores(size_t(size) * size);
      const double ms = MedianMs(3, [&] {
#pragma omp parallel
        {
          const Intersector mine(*grid);
#pragma omp for schedule(dynamic, 4)
          for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
              float3 o, d;
              camera.Ray(x, y, o, d);
              allCores[size_t(y) * size + x] = trace(mine, o, d).t;
            }
        }
      });
      row.mraysCpu = double(size) * size / (ms * 1000.0);
      emit(row, image);
    }
  }
  std::printf("\nwrote out/bench_sdf.csv, out/bench_sdf_fig9.csv and out/bench_sdf_fig10.csv (plots: bench/plot_sdf.py)\n");
  return 0;
}
