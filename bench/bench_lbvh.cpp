// Benchmark in the form of the paper's Tables 1 and 3, for every mesh scripts/fetch-meshes.sh
// cached: BVH build time (Embree LOW and MEDIUM, the LBVH as written, LBVH_CPU, LBVH_ISPC where ISPC
// is found, LBVH_Vulkan on the default device, binned SAH), SAH cost of each tree, and traversal of 1024x1024 primary rays
// (Embree rtcIntersect1 and rtcIntersect16, the latter also over Embree's Morton-code tree (LOW), the LBVH's kind, CrossRT's traversal over the LBVH and SAH trees as
// written, and translated: PrimaryRays_CPU, PrimaryRays_ISPC (one ray a SIMD lane, where ISPC is found; over the
// LBVH and over the SAH tree, the kind Embree MEDIUM builds) and PrimaryRays_Vulkan, which compose BVHScene's
// traversal), with ratios against Embree. Every tracer reads the same batch of rays (4x4 tiles of
// pixels) and writes each hit as a CRT_Hit, as CastRays does. Every figure is measured in this run: the CPU builders and
// the CPU tracers in rounds that run each in turn (7 and 5 unless --build-rounds and --trace-rounds),
// with ratios as medians of the rounds' ratios; the Vulkan figures as medians of 3 after a warm-up.
// Then the speed-against-quality trade of LBVH against binned SAH, as a table and as CSV, which
// bench/plot_bvh_tradeoff.py plots with matplotlib. Embree runs the SIMD width the _ISPC classes run
// (--embree-isa matched, the default: AVX2 when CROSSRT_ISPC_TARGET=avx2 on an AVX-512 CPU, as on a
// CPU without AVX-512), or its widest (--embree-isa native); the header says which.
//
//   bench_lbvh [--load N [--slowdown-csv CSV]] [--embree-isa matched|native] [--build-rounds N] [--trace-rounds N] [--builds-only] [--meshes NAME,...] [MESH_DIR (default build/data/meshes)] [TRADEOFF.csv (default out/bvh_tradeoff.csv)]
// --load N runs N busy threads beside the measurement; warning rows at the end name each translated
// builder or tracer slower than the original (on one thread), _ISPC slower than _CPU, and an _ISPC
// tracer slower than Embree's packets (rtcIntersect16, issue 53's goal; the LBVH walk also against
// rtcIntersect16 over Embree's Morton-code tree, the LBVH's kind). Under load a
// slowdown table follows the build table: the CPU builders' rounds again with the busy threads
// stopped, and each builder's loaded times over its quiet median (median, 90th percentile, slowest),
// with a warning row for a translated builder that slows down more than Embree LOW (TBB's threads);
// the table goes to CSV too (--slowdown-csv, default out/bvh_slowdown.csv), which
// bench/plot_bvh_slowdown.py plots.
#include "BenchMeshes.h"
#include "BenchSupport.h"
#include "BVHScene.h"
#include "CrossRT.h"
#include "LBVH.h"
#include "LBVH_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "LBVH_ISPC.h"
#endif
#include "LBVH_Vulkan.h"
#include "MeshIO.h"
#include "PrimaryRays_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "PrimaryRays_ISPC.h"
#endif
#include "PrimaryRays_Vulkan.h"
#include "SAHBuilder.h"
#include "CommandLine.h"

#include <embree3/rtcore.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

using namespace LiteMath;

namespace {

constexpr int kImageSize = 1024;

double Ms(std::chrono::steady_clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

struct Camera
{
  float3 eye, forward, right, up;
  float4 Ray(int x, int y) const
  {
    const float tanHalf = std::tan(0.5f * 0.7f);  // 40 degrees
    const float px = (2.0f * (x + 0.5f) / kImageSize - 1.0f) * tanHalf, py = (1.0f - 2.0f * (y + 0.5f) / kImageSize) * tanHalf;
    const float3 d = normalize(forward + px * right + py * up);
    return float4(d.x, d.y, d.z, 1e30f);
  }
};

Camera LookAtMesh(const TriangleMesh& mesh)
{
  float3 lo(1e30f), hi(-1e30f);
  for (size_t v = 0; v < mesh.VertexCount(); ++v)
  {
    const float3 p(mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]);
    lo = min(lo, p), hi = max(hi, p);
  }
  const float3 center = 0.5f * (lo + hi);
  Camera c;
  c.eye = center + 1.6f * length(hi - lo) * normalize(float3(0.3f, 0.4f, 1.0f));
  c.forward = normalize(center - c.eye);
  c.right = normalize(cross(c.forward, float3(0, 1, 0)));
  c.up = cross(c.right, c.forward);
  return c;
}

// The Embree device's configuration (rtcNewDevice): "isa=..." caps the SIMD width Embree picks.
std::string g_embreeConfig;

// Embree's name for the ISA of one of crossrt::kIspcTargets, so that Embree runs the SIMD width
// _ISPC runs: "avx2" on an AVX-512 CPU is what an AVX2-only CPU (most desktops) gives both. Embree
// 3 takes a name it does not know as SSE2 without a word, so only these three are passed.
std::string EmbreeIsaOf(const std::string& ispcTarget)
{
  if (ispcTarget == "sse4") return "sse4.2";
  if (ispcTarget == "avx2") return "avx2";
  if (ispcTarget == "avx512skx") return "avx512";
  return "";
}

struct TradeOff { std::string mesh; double lbvhBuildMs, lbvhMrays, sahBuildMs, sahMrays; };

// The trade as CSV, which bench/plot_bvh_tradeoff.py plots.
bool WriteTradeOffCsv(const std::vector<TradeOff>& rows, const std::string& path)
{
  std::FILE* f = OpenCsv(path, "bench_lbvh");
  if (!f) return false;
  std::fprintf(f, "mesh,lbvh_build_ms,lbvh_mrays_per_s,sah_build_ms,sah_mrays_per_s\n");
  for (auto& r : rows) std::fprintf(f, "%s,%.3f,%.3f,%.3f,%.3f\n", r.mesh.c_str(), r.lbvhBuildMs, r.lbvhMrays, r.sahBuildMs, r.sahMrays);
  return std::fclose(f) == 0;
}

// How much one CPU builder slowed down under --load: its quiet median and its loaded times over it.
struct Slowdown { std::string mesh, builder; double quietMs, median, p90, worst; };

// The slowdown table as CSV, which bench/plot_bvh_slowdown.py plots.
bool WriteSlowdownCsv(const std::vector<Slowdown>& rows, const std::string& path, const std::string& cpu, const std::string& ispcTarget, int load)
{
  std::FILE* f = OpenCsv(path, "bench_lbvh");
  if (!f) return false;
  std::fprintf(f, "cpu,ispc_target,busy_threads,mesh,builder,quiet_ms,loaded_median_x,loaded_p90_x,loaded_worst_x\n");
  for (auto& r : rows)
    std::fprintf(f, "\"%s\",%s,%d,%s,%s,%.4f,%.3f,%.3f,%.3f\n", cpu.c_str(), ispcTarget.c_str(), load, r.mesh.c_str(), r.builder.c_str(), r.quietMs,
                 r.median, r.p90, r.worst);
  return std::fclose(f) == 0;
}

}  // namespace

int main(int argc, char** argv)
{
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // tables appear as they are measured
  std::vector<std::string> only;
  int load = 0, buildRounds = 7, traceRounds = 5;
  bool buildsOnly = false;
  std::string dir = "build/data/meshes", csvPath = "out/bvh_tradeoff.csv";
  std::string slowdownCsv = "out/bvh_slowdown.csv";
  std::string embreeIsa = "matched";
  crossrt::CommandLine app("bench_lbvh",
                           "BVH build and traversal against Embree on the meshes scripts/fetch-meshes.sh cached in MESH_DIR, in the\n"
                           "form of the paper's Tables 1 and 3. The speed-against-quality table goes to TRADEOFF.csv too;\n"
                           "bench/plot_bvh_tradeoff.py plots it.");
  app.add_option("MESH_DIR", dir, "the meshes' folder");
  app.add_option("TRADEOFF.csv", csvPath, "the trade-off table's CSV file");
  app.add_option("--load", load, "busy threads beside every measurement (a user's machine is never quiet)")->check(CLI::Range(0, 256));
  app.add_option("--meshes", only, "only the meshes whose file names start with one of these (e.g. teapot,dragon_vrip_res4)")->delimiter(',');
  app.add_flag("--builds-only", buildsOnly, "the build table alone (no traversal, no trade-off table or CSV)");
  app.add_option("--slowdown-csv", slowdownCsv, "under --load: where the slowdown table goes as CSV (bench/plot_bvh_slowdown.py plots it)");
  app.add_option("--build-rounds", buildRounds, "interleaved rounds of the CPU builders: more for a loaded machine")->check(CLI::Range(1, 1000));
  app.add_option("--trace-rounds", traceRounds, "interleaved rounds of the CPU tracers: more for a noisy machine")->check(CLI::Range(1, 1000));
  app.add_option("--embree-isa", embreeIsa,
                 "the SIMD width Embree may use: 'matched' (the ISPC target's: avx2 when CROSSRT_ISPC_TARGET=avx2) or 'native' (its widest)")
      ->check(CLI::IsMember({"matched", "native"}));
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  if (embreeIsa == "matched" && !EmbreeIsaOf(crossrt::IspcTargetInUse()).empty()) g_embreeConfig = "isa=" + EmbreeIsaOf(crossrt::IspcTargetInUse());
  auto chosen = [&](const std::string& name) {
    if (only.empty()) return true;
    for (auto& prefix : only)
      if (name.rfind(prefix, 0) == 0) return true;
    return false;
  };
  const char* names[] = {"teapot.obj", "dragon_vrip_res4.ply.gz", "dragon_vrip_res3.ply.gz", "armadillo.off", "bunny00.off",
                         "dragon_vrip_res2.ply.gz", "dragon_vrip.ply.gz"};
  std::shared_ptr<crossrt::VulkanContext> ctx;
  try { ctx = crossrt::VulkanContext::CreateDefault(); }
  catch (const std::exception& e) { std::printf("no Vulkan device (%s): the _Vulkan column is left out\n", e.what()); }
  BusyThreads busy(load);  // stopped for the quiet rounds of the slowdown table
  std::printf("CPU: %s, %d threads; ISPC target: %s (%s); Embree ISA: %s; Vulkan device: %s; load: %d busy threads beside the measurement\n",
              CpuModel().c_str(), omp_get_max_threads(), crossrt::IspcTargetInUse().c_str(), IspcLanes(),
              g_embreeConfig.empty() ? "its widest" : g_embreeConfig.substr(4).c_str(), ctx ? ctx->DeviceName().c_str() : "none", busy.Count());
  std::vector<std::string> slower;  // translated classes slower than the original, for the warning rows at the end
  std::vector<Slowdown> slowdowns;  // under --load: the slowdown table's rows
  int status = 0;                   // 1 once a table could not be written

  std::printf("\nBuild time, ms (ratio = time / Embree LOW; the CPU builders' medians of %d interleaved rounds, their ratios\n"
              "medians of the rounds' ratios; Vulkan: median of 3 wall times with copies, its ratio one of medians, [GPU time])\n",
              buildRounds);
  std::printf("| %-22s | %9s | %10s | %12s | %15s | %15s | %15s | %23s | %15s |\n", "mesh", "triangles", "Embree LOW", "Embree MEDIUM",
              "LBVH original", "LBVH_CPU", "LBVH_ISPC", "LBVH_Vulkan", "binned SAH");
  std::printf("|%s|\n", std::string(164, '-').c_str());
  struct Row { std::string name; TriangleMesh mesh; BVHTree lbvh, sah; double lbvhCpuMs, sahMs; };
  std::vector<Row> rows;
  auto lbvhCpu = CreateLBVH_CPU();
#ifdef CROSSRT_HAS_ISPC
  std::shared_ptr<LBVH> lbvhIspc = CreateLBVH_ISPC();
#else
  std::shared_ptr<LBVH> lbvhIspc;
#endif
  std::shared_ptr<LBVH> lbvhGpu = ctx ? CreateLBVH_Vulkan(ctx) : nullptr;
  for (const char* name : names)
  {
    if (!chosen(name)) continue;
    const std::string path = dir + "/" + name;
    if (!std::filesystem::exists(path))
    {
      std::printf("| %-22s | skipped: not in %s (run scripts/fetch-meshes.sh)\n", name, dir.c_str());
      continue;
    }
    Row row{name, LoadMesh(path), {}, {}, 0.0, 0.0};
    const std::vector<Box4f> boxes = TriangleBoxes(row.mesh);
    const int n = int(boxes.size());
    EmbreeMesh embree(g_embreeConfig);
    LBVH original;
    original.Reserve(n);
    lbvhCpu->Reserve(n);
    lbvhCpu->CommitDeviceData();
    if (lbvhIspc)
    {
      lbvhIspc->Reserve(n);
      lbvhIspc->CommitDeviceData();
    }
    // The CPU builders in interleaved rounds (7 unless --build-rounds); ratios to Embree LOW are medians of per-round ratios.
    const auto cpuMs = InterleavedMs({[&] { embree.Build(row.mesh, RTC_BUILD_QUALITY_LOW); },
                                      [&] { embree.Build(row.mesh, RTC_BUILD_QUALITY_MEDIUM); },
                                      [&] { original.Build(n, boxes.data()); }, [&] { lbvhCpu->Build(n, boxes.data()); },
                                      [&] { row.sah = BuildBinnedSAH(boxes.data(), n); },
                                      [&] {
                                        if (lbvhIspc)
                                          lbvhIspc->Build(n, boxes.data());
                                      }},
                                     buildRounds);
    if (busy.Count() > 0)
    {
      // The same builders quiet, after the loaded rounds (so that the loaded ones are measured as
      // without this table): how much each slows down under the load, Embree's TBB build the peer.
      busy.Stop();
      const auto quietMs = InterleavedMs({[&] { embree.Build(row.mesh, RTC_BUILD_QUALITY_LOW); }, [&] { original.Build(n, boxes.data()); },
                                          [&] { lbvhCpu->Build(n, boxes.data()); },
                                          [&] {
                                            if (lbvhIspc)
                                              lbvhIspc->Build(n, boxes.data());
                                          }},
                                         buildRounds);
      busy.Start();
      const int loadedOf[] = {0, 2, 3, 5};
      const char* builders[] = {"Embree LOW", "LBVH original", "LBVH_CPU", "LBVH_ISPC"};
      for (int b = 0; b < (lbvhIspc ? 4 : 3); ++b)
      {
        const double quiet = MedianOf(quietMs[b]);
        const std::vector<double>& loaded = cpuMs[loadedOf[b]];
        slowdowns.push_back({name, builders[b], quiet, MedianOf(loaded) / quiet, QuantileOf(loaded, 0.9) / quiet, QuantileOf(loaded, 1.0) / quiet});
        const Slowdown& embree = slowdowns[slowdowns.size() - b - 1], &mine = slowdowns.back();
        auto above = [](double a, double b) { return std::lround(a * 100.0) > std::lround(b * 100.0); };  // as printed
        if (b >= 2 && (above(mine.median, embree.median) || above(mine.p90, embree.p90)))
        {
          char warning[256];
          std::snprintf(warning, sizeof(warning), "%s: %s slows down under load %.2fx (90th percentile %.2fx), Embree LOW %.2fx (%.2fx)", name,
                        builders[b], mine.median, mine.p90, embree.median, embree.p90);
          slower.push_back(warning);
        }
      }
    }
    const double low = MedianOf(cpuMs[0]), medium = MedianOf(cpuMs[1]), originalMs = MedianOf(cpuMs[2]);
    row.lbvh = original.Tree(n);
    row.lbvhCpuMs = MedianOf(cpuMs[3]);
    char gpu[64] = "n/a";
    if (lbvhGpu && !buildsOnly)
    {
      lbvhGpu->Reserve(n);
      lbvhGpu->CommitDeviceData();
      const double wall = MedianMs(3, [&] { lbvhGpu->Build(n, boxes.data()); });
      float times[4];
      lbvhGpu->GetExecutionTime("Build", times);
      std::snprintf(gpu, sizeof(gpu), "%7.1f (%4.2fx) [%6.1f]", wall, wall / low, times[0]);
    }
    row.sahMs = MedianOf(cpuMs[4]);
    char ispc[24] = "no ISPC";
    if (lbvhIspc)
    {
      const BVHTree tree = lbvhIspc->Tree(n);
      if (tree.nodes.size() != row.lbvh.nodes.size() ||
          std::memcmp(tree.nodes.data(), row.lbvh.nodes.data(), tree.nodes.size() * sizeof(BVHNode)) != 0)
        std::fprintf(stderr, "bench_lbvh: %s: LBVH_ISPC built another tree than the original\n", name);
      std::snprintf(ispc, sizeof(ispc), "%7.1f (%5.2fx)", MedianOf(cpuMs[5]), PairedRatio(cpuMs[5], cpuMs[0]));
    }
    std::printf("| %-22s | %9d | %10.1f | %6.1f (%4.2fx) | %7.1f (%5.2fx) | %7.1f (%5.2fx) | %15s | %23s | %7.1f (%5.2fx) |\n", name, n, low,
                medium, PairedRatio(cpuMs[1], cpuMs[0]), originalMs, PairedRatio(cpuMs[2], cpuMs[0]), row.lbvhCpuMs,
                PairedRatio(cpuMs[3], cpuMs[0]), ispc, gpu, row.sahMs, PairedRatio(cpuMs[4], cpuMs[0]));
    // Warning rows: a translated builder slower than the original (one thread), or _ISPC slower than _CPU.
    auto slowerThan = [&](int work, int base, const char* what, const char* than) {
      const double ratio = PairedRatio(cpuMs[work], cpuMs[base]);
      if (ratio > 1.0)
        slower.push_back(std::string(name) + ": " + what + " builds at " + std::to_string(ratio).substr(0, 4) + "x the time of " + than);
    };
    slowerThan(3, 2, "LBVH_CPU", "the original");
    if (lbvhIspc)
    {
      slowerThan(5, 2, "LBVH_ISPC", "the original");
      slowerThan(5, 3, "LBVH_ISPC", "LBVH_CPU");
    }
    rows.push_back(std::move(row));
  }

  if (!slowdowns.empty())
  {
    std::printf("\nSlowdown under load: each CPU builder's quiet median, ms (the same rounds again after the loaded ones, with\n"
                "the %d busy threads stopped), then its loaded time over that: median, 90th percentile and slowest of the rounds\n",
                busy.Count());
    std::printf("| %-22s | %-31s | %-31s | %-31s | %-31s |\n", "mesh", "Embree LOW (TBB)", "LBVH original (1 thread)", "LBVH_CPU", "LBVH_ISPC");
    std::printf("| %-22s |", "");
    for (int b = 0; b < 4; ++b) std::printf(" %6s %7s %7s %8s |", "quiet", "median", "p90", "worst");
    std::printf("\n|%s|\n", std::string(158, '-').c_str());
    for (size_t r = 0; r < slowdowns.size(); ++r)
    {
      const Slowdown& d = slowdowns[r];
      if (r == 0 || d.mesh != slowdowns[r - 1].mesh) std::printf("%s| %-22s |", r == 0 ? "" : "\n", d.mesh.c_str());
      std::printf(" %6.1f %6.2fx %6.2fx %7.2fx |", d.quietMs, d.median, d.p90, d.worst);
    }
    std::printf("\n");
    if (!WriteSlowdownCsv(slowdowns, slowdownCsv, CpuModel(), crossrt::IspcTargetInUse(), busy.Count()))
      status = 1;
    else
      std::printf("table: %s (plot it: bench/plot_bvh_slowdown.py %s out/bvh_slowdown.png)\n", slowdownCsv.c_str(), slowdownCsv.c_str());
  }

  // The warning rows, after the last table this run prints.
  auto printSlower = [&] {
    if (slower.empty()) return;
    std::printf("\nWARNING: translated classes slower than they should be (load: %d busy threads):\n", busy.Count());
    for (auto& line : slower) std::printf("| WARNING | %s |\n", line.c_str());
  };
  if (buildsOnly)
  {
    printSlower();
    return status;
  }

  std::printf("\nTraversal of %dx%d primary rays, Mrays/s, all %d threads but 1T (ratio against Embree rtcIntersect1 on all\n"
              "threads: medians of %d interleaved rounds' ratios; _Vulkan: median of 3, its ratio one of medians); SAH cost of the trees.\n"
              "Embree 16 LOW: rtcIntersect16 over Embree's Morton-code build (RTC_BUILD_QUALITY_LOW), the kind of tree an LBVH is\n"
              "Each tracer reads the same rays (4x4 tiles of pixels, in rows of tiles) and writes CRT_Hit (t, ids, u, v), as CastRays does\n"
              "ray queries [GPU]: PrimaryRays_Vulkan on the device's ray tracing hardware, Mrays/s of GPU time (x its translated traversal's,\n"
              "the GPU-time ratio of Table 6's hardware column; on lavapipe both run on the CPU: only the ratio means anything)\n",
              kImageSize, kImageSize, omp_get_max_threads(), traceRounds);
  std::printf("| %-22s | %9s | %15s | %15s | %15s | %15s | %15s | %15s | %15s | %15s | %23s | %16s | %9s | %9s | %8s |\n", "mesh",
              "Embree 1", "Embree 16", "Embree 16 LOW", "CrossRT LBVH", "CrossRT LBVH 1T", "LBVH _CPU", "LBVH _ISPC", "CrossRT SAH", "SAH _ISPC", "LBVH _Vulkan [GPU]",
              "ray queries [GPU]", "SAH cost L", "SAH cost S", "same hit");
  std::printf("|%s|\n", std::string(267, '-').c_str());
  // The translated traversal: PrimaryRays_CPU / _Vulkan trace ray batches through the composed BVHScene.
  auto castCpu = CreatePrimaryRays_CPU(1, 1);
#ifdef CROSSRT_HAS_ISPC
  std::shared_ptr<PrimaryRays> castIspc = CreatePrimaryRays_ISPC(1, 1), castIspcSah = CreatePrimaryRays_ISPC(1, 1);
#else
  std::shared_ptr<PrimaryRays> castIspc, castIspcSah;
  std::printf("no ISPC compiler was found at configure time: the _ISPC column is left out\n");
#endif
  std::shared_ptr<PrimaryRays> castGpu;
  try
  {
    castGpu = CreatePrimaryRays_Vulkan(1, 1);
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "bench_lbvh: no Vulkan device, skipping PrimaryRays_Vulkan: %s\n", e.what());
  }
  std::vector<TradeOff> trade;
  for (Row& row : rows)
  {
    const Camera cam = LookAtMesh(row.mesh);
    const int pixels = kImageSize * kImageSize;
    EmbreeMesh embree(g_embreeConfig), embreeLow(g_embreeConfig);
    embree.Build(row.mesh, RTC_BUILD_QUALITY_MEDIUM);
    // Embree's Morton-code build (LOW), the kind of tree an LBVH is: the LBVH walk's like-for-like peer.
    embreeLow.Build(row.mesh, RTC_BUILD_QUALITY_LOW);
    // Every tracer reads the same batch of rays, as PrimaryRays::CastRays takes it (4x4 tiles of
    // pixels, the tiles in rows: the order a renderer hands out coherent rays), and writes each
    // nearest hit as a CRT_Hit: the same work on both sides of each ratio.
    std::vector<float4> rayPos(pixels, float4(cam.eye.x, cam.eye.y, cam.eye.z, 0.0f)), rayDir(pixels);
    for (int i = 0; i < pixels; ++i)
    {
      const int tile = i / 16, k = i % 16;
      rayDir[i] = cam.Ray(tile % (kImageSize / 4) * 4 + k % 4, tile / (kImageSize / 4) * 4 + k / 4);
    }
    std::vector<CRT_Hit> embreeHits(pixels), embreePacketHits(pixels), embreeLowHits(pixels), ourHits(pixels), ourHits1T(pixels), sahHits(pixels);
    auto embreeHit = [](const RTCRayHit& rh, float tfar) {
      CRT_Hit h{};
      const bool missed = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID;
      h.t = missed ? tfar : rh.ray.tfar;
      h.primId = missed ? 0xFFFFFFFFu : rh.hit.primID;
      h.instId = missed ? 0xFFFFFFFFu : rh.hit.instID[0] == RTC_INVALID_GEOMETRY_ID ? 0u : rh.hit.instID[0];
      h.geomId = missed ? 0xFFFFFFFFu : rh.hit.geomID;
      h.coords[0] = rh.hit.u, h.coords[1] = rh.hit.v;
      return h;
    };
    auto embreeSingle = [&] {
#pragma omp parallel for schedule(dynamic, 4)
      for (int b = 0; b < pixels / 256; ++b)
      {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        for (int i = 256 * b; i < 256 * (b + 1); ++i)
        {
          RTCRayHit rh{};
          rh.ray.org_x = rayPos[i].x, rh.ray.org_y = rayPos[i].y, rh.ray.org_z = rayPos[i].z, rh.ray.tnear = rayPos[i].w;
          rh.ray.dir_x = rayDir[i].x, rh.ray.dir_y = rayDir[i].y, rh.ray.dir_z = rayDir[i].z, rh.ray.tfar = rayDir[i].w;
          rh.ray.mask = 0xFFFFFFFFu;
          rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
          rtcIntersect1(embree.scene, &context, &rh);
          embreeHits[i] = embreeHit(rh, rayDir[i].w);
        }
      }
    };
    auto embreePacket = [&](RTCScene scene, std::vector<CRT_Hit>& hits) {
#pragma omp parallel for schedule(dynamic, 16)
      for (int b = 0; b < pixels / 16; ++b)
      {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        alignas(64) RTCRayHit16 rh;
        alignas(64) int valid[16];
        for (int k = 0; k < 16; ++k)
        {
          const int i = 16 * b + k;
          valid[k] = -1;
          rh.ray.org_x[k] = rayPos[i].x, rh.ray.org_y[k] = rayPos[i].y, rh.ray.org_z[k] = rayPos[i].z, rh.ray.tnear[k] = rayPos[i].w;
          rh.ray.dir_x[k] = rayDir[i].x, rh.ray.dir_y[k] = rayDir[i].y, rh.ray.dir_z[k] = rayDir[i].z, rh.ray.tfar[k] = rayDir[i].w;
          rh.ray.mask[k] = 0xFFFFFFFFu, rh.ray.time[k] = 0.0f, rh.ray.flags[k] = 0, rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect16(valid, scene, &context, &rh);
        for (int k = 0; k < 16; ++k)
        {
          RTCRayHit one{};
          one.ray.tfar = rh.ray.tfar[k], one.hit.geomID = rh.hit.geomID[k], one.hit.primID = rh.hit.primID[k];
          one.hit.instID[0] = rh.hit.instID[0][k], one.hit.u = rh.hit.u[k], one.hit.v = rh.hit.v[k];
          hits[16 * b + k] = embreeHit(one, rayDir[16 * b + k].w);
        }
      }
    };
    auto traceWith = [&](ISceneObject& scene, int threads, std::vector<CRT_Hit>& hits) {
      return [&scene, threads, &hits, &rayPos, &rayDir, pixels] {
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
        for (int i = 0; i < pixels; ++i)
          hits[i] = scene.RayQuery_NearestHit(rayPos[i], rayDir[i]);
      };
    };
    const BVHTree lbvhTree = row.lbvh, sahTree = row.sah;
    // Scenes over the trees built above; their one-instance top level gets a tree of its own.
    auto reuse = [](const BVHTree& tree) {
      return [&tree](const Box4f* boxes, int n) { return n == int(tree.primIndices.size()) ? tree : BuildBinnedSAH(boxes, n); };
    };
    BVHScene lbvhScene("lbvh", reuse(lbvhTree));
    BVHScene sahScene("sah", reuse(sahTree));
    for (BVHScene* s : {&lbvhScene, &sahScene})
    {
      s->AddInstance(s->AddGeom_Triangles3f(row.mesh.positions.data(), row.mesh.VertexCount(), row.mesh.indices.data(), row.mesh.indices.size()),
                     float4x4());
      s->CommitScene();
    }
    const int threads = omp_get_max_threads();
    auto mrays = [&](double ms) { return pixels / ms / 1e3; };
    std::vector<CRT_Hit> castHits(pixels), ispcHits(pixels), ispcSahHits(pixels);
    std::shared_ptr<ISceneObject> lbvhShared(&lbvhScene, [](ISceneObject*) {});  // live on this stack frame
    std::shared_ptr<ISceneObject> sahShared(&sahScene, [](ISceneObject*) {});
    castCpu->SetScene(lbvhShared, {}, {});
    if (castIspc)
    {
      castIspc->SetScene(lbvhShared, {}, {});
      castIspcSah->SetScene(sahShared, {}, {});
    }
    // The CPU tracers in interleaved rounds, as the builders above: ratios are medians of per-round ratios.
    const auto traceMs = InterleavedMs({embreeSingle, [&] { embreePacket(embree.scene, embreePacketHits); }, traceWith(lbvhScene, threads, ourHits),
                                        traceWith(lbvhScene, 1, ourHits1T),
                                        [&] { castCpu->CastRays(rayPos.data(), rayDir.data(), castHits.data(), pixels); },
                                        traceWith(sahScene, threads, sahHits),
                                        [&] {
                                          if (castIspc)
                                            castIspc->CastRays(rayPos.data(), rayDir.data(), ispcHits.data(), pixels);
                                        },
                                        [&] {
                                          if (castIspcSah)
                                            castIspcSah->CastRays(rayPos.data(), rayDir.data(), ispcSahHits.data(), pixels);
                                        },
                                        [&] { embreePacket(embreeLow.scene, embreeLowHits); }},
                                       traceRounds);
    const double embree1 = MedianOf(traceMs[0]), embree16 = MedianOf(traceMs[1]), lbvhMs = MedianOf(traceMs[2]), lbvh1T = MedianOf(traceMs[3]),
                 castCpuMs = MedianOf(traceMs[4]), sahMs = MedianOf(traceMs[5]);
    auto againstEmbree1 = [&](int work) { return PairedRatio(traceMs[0], traceMs[work]); };  // throughput ratio
    // Each translated tracer against the original's walk over the same tree: rays on another
    // triangle, and of those the ones at another distance. A ray through an edge or vertex shared
    // by triangles may take either of them where the arithmetic differs (a GPU's fused
    // multiply-adds), at the same t; another t is a wrong hit.
    std::string differences;
    auto compare = [&](const char* tracer, const std::vector<CRT_Hit>& hits, const std::vector<CRT_Hit>& reference) {
      size_t other = 0, otherT = 0;
      for (int i = 0; i < pixels; ++i)
        if (hits[i].primId != reference[i].primId)
        {
          ++other;
          otherT += !(std::fabs(hits[i].t - reference[i].t) <= 1e-5f * std::fabs(reference[i].t));
        }
      if (other > 0)
        differences += std::string(differences.empty() ? "" : "; ") + tracer + ": " + std::to_string(other) + " rays on another triangle, " +
                       std::to_string(otherT) + " of them at another distance";
    };
    compare("LBVH _CPU", castHits, ourHits);
    char ispcCast[24] = "no ISPC", ispcSahCast[24] = "no ISPC";
    if (castIspc)
    {
      compare("LBVH _ISPC", ispcHits, ourHits);
      compare("SAH _ISPC", ispcSahHits, sahHits);
      std::snprintf(ispcCast, sizeof(ispcCast), "%6.2f (%5.2fx)", mrays(MedianOf(traceMs[6])), againstEmbree1(6));
      std::snprintf(ispcSahCast, sizeof(ispcSahCast), "%6.2f (%5.2fx)", mrays(MedianOf(traceMs[7])), againstEmbree1(7));
      castIspc->SetScene(nullptr, {}, {});
      castIspcSah->SetScene(nullptr, {}, {});
    }
    char gpuCast[48] = "no device", gpuHardware[32] = "no ray queries";
    if (castGpu)
    {
      // The translated traversal, then (where the device has them) ray queries on the same scene.
      auto* vulkan = dynamic_cast<PrimaryRays_Vulkan*>(castGpu.get());
      vulkan->UseRayTracingHardware(false);
      castGpu->SetScene(lbvhShared, {}, {});
      castGpu->CommitDeviceData();
      const double wall = MedianMs(3, [&] { castGpu->CastRays(rayPos.data(), rayDir.data(), castHits.data(), pixels); });
      float times[4];
      castGpu->GetExecutionTime("CastRays", times);
      const double softwareGpuMs = times[0];
      compare("LBVH _Vulkan", castHits, ourHits);
      std::snprintf(gpuCast, sizeof(gpuCast), "%6.2f (%5.2fx) [%5.2f]", mrays(wall), embree1 / wall, pixels / times[0] / 1e3);
      if (ctx && ctx->hasRayQuery)
      {
        vulkan->UseRayTracingHardware(true);
        castGpu->CommitDeviceData();
        MedianMs(3, [&] { castGpu->CastRays(rayPos.data(), rayDir.data(), castHits.data(), pixels); });
        castGpu->GetExecutionTime("CastRays", times);
        std::snprintf(gpuHardware, sizeof(gpuHardware), "%6.2f (%5.2fx)", pixels / times[0] / 1e3, softwareGpuMs / times[0]);
      }
      castGpu->SetScene(nullptr, {}, {});
    }
    castCpu->SetScene(nullptr, {}, {});
    if (!differences.empty())
      std::fprintf(stderr, "bench_lbvh: %s: the translated traversal differs from the original: %s\n", row.name.c_str(), differences.c_str());
    size_t same = 0;
    for (int i = 0; i < pixels; ++i) same += ourHits[i].primId == embreeHits[i].primId;
    std::printf("| %-22s | %9.2f | %6.2f (%5.2fx) | %6.2f (%5.2fx) | %6.2f (%5.2fx) | %6.2f (%5.2fx) | %6.2f (%5.2fx) | %15s | %6.2f (%5.2fx) | %15s | %23s | %16s | %9.1f | %9.1f | %7.4f%% |\n",
                row.name.c_str(), mrays(embree1), mrays(embree16), againstEmbree1(1), mrays(MedianOf(traceMs[8])), againstEmbree1(8), mrays(lbvhMs),
                againstEmbree1(2), mrays(lbvh1T),
                againstEmbree1(3), mrays(castCpuMs), againstEmbree1(4), ispcCast, mrays(sahMs), againstEmbree1(5), ispcSahCast, gpuCast, gpuHardware,
                SAHCost(row.lbvh), SAHCost(row.sah), 100.0 * same / pixels);
    trade.push_back({row.name, row.lbvhCpuMs, mrays(lbvhMs), row.sahMs, mrays(sahMs)});
    // Warning rows: a translated tracer slower than the original traversal on one thread, _ISPC below
    // _CPU, or _ISPC below Embree's packets.
    auto slowerTrace = [&](int work, int base, const char* what, const char* than) {
      const double ratio = PairedRatio(traceMs[work], traceMs[base]);
      if (ratio > 1.0)
        slower.push_back(row.name + ": " + what + " traces at " + std::to_string(1.0 / ratio).substr(0, 4) + "x the speed of " + than);
    };
    slowerTrace(4, 3, "LBVH _CPU", "the original on one thread");
    if (castIspc)
    {
      slowerTrace(6, 3, "LBVH _ISPC", "the original on one thread");
      slowerTrace(6, 4, "LBVH _ISPC", "LBVH _CPU");
      slowerTrace(6, 1, "LBVH _ISPC", "Embree rtcIntersect16");
      slowerTrace(6, 8, "LBVH _ISPC", "Embree rtcIntersect16 over its Morton tree (LOW)");
      slowerTrace(7, 1, "SAH _ISPC", "Embree rtcIntersect16");
    }
  }

  std::printf("\nSpeed against quality: LBVH (LBVH_CPU build) against binned SAH\n");
  std::printf("| %-22s | %14s | %14s | %14s | %14s | %22s |\n", "mesh", "LBVH build ms", "LBVH Mrays/s", "SAH build ms", "SAH Mrays/s",
              "SAH pays off after");
  std::printf("|%s|\n", std::string(123, '-').c_str());
  for (auto& t : trade)
  {
    // Rays after which SAH's extra build time is repaid by its faster tracing.
    const double perRayLbvh = 1e-3 / t.lbvhMrays, perRaySah = 1e-3 / t.sahMrays;  // ms per ray
    const double breakEven = perRaySah < perRayLbvh ? (t.sahBuildMs - t.lbvhBuildMs) / (perRayLbvh - perRaySah) : -1.0;
    char after[32];
    if (breakEven < 0) std::snprintf(after, sizeof(after), "never");
    else std::snprintf(after, sizeof(after), "%.1f Mrays", breakEven / 1e6);
    std::printf("| %-22s | %14.1f | %14.2f | %14.1f | %14.2f | %22s |\n", t.mesh.c_str(), t.lbvhBuildMs, t.lbvhMrays, t.sahBuildMs,
                t.sahMrays, after);
  }
  printSlower();
  if (!WriteTradeOffCsv(trade, csvPath)) return 1;
  std::printf("table: %s (plot it: bench/plot_bvh_tradeoff.py %s out/bvh_tradeoff.png)\n", csvPath.c_str(), csvPath.c_str());
  return status;
}
