// A program's first BVH build, as a program that builds once sees it: each builder's first Build in
// a process of its own (a child of this one), on the meshes scripts/fetch-meshes.sh cached. The
// builds of bench_lbvh come after three untimed calls, by which each _ISPC kernel has chosen
// between its SIMD lanes and its scalar loop (crossrt::LaneChoice); a program's first calls come
// before. LBVH_ISPC runs as a program that builds once a run does, on a machine where it never ran
// (a new CROSSRT_LANE_MEMORY file, crossrt::LaneMemory):
// - run 1: nothing remembered, each kernel runs in lanes;
// - run 2: each kernel's scalar loop, the way with no time yet;
// - runs 3 on: each kernel the way whose first call was faster.
// Embree LOW and LBVH_CPU (no choices to make) are the medians of --children runs (5), LBVH_ISPC's
// runs 1 and 2 the medians of 3 such programs' and runs 3 on the median of --children runs after
// those; each ratio is the time over LBVH_CPU's first build. The table goes to CSV too
// (bench/plot_first_build.py plots it).
//
//   bench_first_build [--meshes NAME,...] [--children N] [MESH_DIR (default build/data/meshes)] [CSV (default out/first_build.csv)]
#include "BenchMeshes.h"
#include "BenchSupport.h"
#include "CommandLine.h"
#include "LBVH.h"
#include "LBVH_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "LBVH_ISPC.h"
#endif
#include "MeshIO.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

using LiteMath::Box4f;

namespace {

double MsSince(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The child: builds the mesh once with one builder and prints the build's ms.
int RunChild(const std::string& builder, const std::string& path)
{
  const TriangleMesh mesh = LoadMesh(path);
  if (builder == "embree")
  {
    EmbreeMesh embree;
    std::printf("%.4f\n", embree.Build(mesh, RTC_BUILD_QUALITY_LOW));
    return 0;
  }
  std::shared_ptr<LBVH> lbvh;
  if (builder == "lbvh_cpu") lbvh = CreateLBVH_CPU();
#ifdef CROSSRT_HAS_ISPC
  if (builder == "lbvh_ispc") lbvh = CreateLBVH_ISPC();
#endif
  if (!lbvh)
  {
    std::fprintf(stderr, "bench_first_build: no builder '%s' here\n", builder.c_str());
    return 2;
  }
  const std::vector<Box4f> boxes = TriangleBoxes(mesh);
  lbvh->Reserve(int(boxes.size()));
  lbvh->CommitDeviceData();
  const auto t0 = std::chrono::steady_clock::now();
  lbvh->Build(int(boxes.size()), boxes.data());
  std::printf("%.4f\n", MsSince(t0));
  return 0;
}

std::string Quoted(const std::string& s)
{
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// One child's first build, in ms (negative where it failed), with CROSSRT_LANE_MEMORY=memory.
double ChildMs(const std::string& self, const std::string& builder, const std::string& mesh, const std::string& memory)
{
  const std::string command = "CROSSRT_LANE_MEMORY=" + Quoted(memory) + " " + Quoted(self) + " --child " + builder + " " + Quoted(mesh);
  std::FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return -1.0;
  double ms = -1.0;
  if (std::fscanf(pipe, "%lf", &ms) != 1) ms = -1.0;
  return pclose(pipe) == 0 ? ms : -1.0;
}

}  // namespace

int main(int argc, char** argv)
{
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::vector<std::string> only;
  std::string dir = "build/data/meshes", csvPath = "out/first_build.csv", child;
  int children = 5;
  crossrt::CommandLine app("bench_first_build",
                           "A program's first BVH build: each builder's first Build in a fresh process, LBVH_ISPC in the first,\n"
                           "second and later runs of a program that builds once (crossrt::LaneMemory), against LBVH_CPU and Embree LOW.\n"
                           "The table goes to CSV too; bench/plot_first_build.py plots it.");
  app.add_option("MESH_DIR", dir, "the meshes' folder (a mesh file, with --child)");
  app.add_option("CSV", csvPath, "the table's CSV file");
  app.add_option("--meshes", only, "only the meshes whose file names start with one of these (e.g. bunny,dragon_vrip_res2)")->delimiter(',');
  app.add_option("--children", children, "fresh processes per cell (the median is printed)")->check(CLI::Range(1, 100));
  app.add_option("--child", child, "(internal) build MESH_DIR, a mesh file, with this builder and print the first build's ms")
      ->check(CLI::IsMember({"embree", "lbvh_cpu", "lbvh_ispc"}));
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  if (!child.empty()) return RunChild(child, dir);

  const std::string self = std::filesystem::canonical("/proc/self/exe").string();
  const std::string memory = (std::filesystem::temp_directory_path() / ("crossrt_first_build_" + std::to_string(getpid()) + ".tsv")).string();
  std::printf("CPU: %s, %d threads; ISPC target: %s; each cell the median of %d fresh processes' first build\n", CpuModel().c_str(),
              int(std::thread::hardware_concurrency()), crossrt::IspcTargetInUse().c_str(), children);
  std::printf("| %-24s | %9s | %10s | %8s | %19s | %19s | %19s |\n", "mesh", "triangles", "Embree LOW", "LBVH_CPU", "LBVH_ISPC run 1",
              "LBVH_ISPC run 2", "LBVH_ISPC runs 3 on");
  std::printf("|%s|\n", std::string(134, '-').c_str());
  std::FILE* csv = OpenCsv(csvPath, "bench_first_build");
  if (csv)
    std::fprintf(csv, "cpu,ispc_target,mesh,triangles,embree_low_ms,lbvh_cpu_ms,lbvh_ispc_run1_ms,lbvh_ispc_run2_ms,lbvh_ispc_later_ms\n");
  const char* names[] = {"teapot.obj", "dragon_vrip_res4.ply.gz", "dragon_vrip_res3.ply.gz", "armadillo.off", "bunny00.off",
                         "dragon_vrip_res2.ply.gz", "dragon_vrip.ply.gz"};
  int status = 0;
  for (const char* name : names)
  {
    bool chosen = only.empty();
    for (const auto& prefix : only) chosen = chosen || std::string(name).rfind(prefix, 0) == 0;
    const std::string path = dir + "/" + name;
    if (!chosen) continue;
    if (!std::filesystem::exists(path))
    {
      std::printf("| %-24s | skipped: not in %s (run scripts/fetch-meshes.sh)\n", name, dir.c_str());
      continue;
    }
    const size_t triangles = LoadMesh(path).TriangleCount();
    auto median = [&](const std::string& builder, const std::string& memoryFile) {
      std::vector<double> ms;
      for (int k = 0; k < children; ++k)
      {
        const double m = ChildMs(self, builder, path, memoryFile);
        if (m < 0.0) return -1.0;
        ms.push_back(m);
      }
      return MedianOf(ms);
    };
    const double embree = median("embree", "off"), cpu = median("lbvh_cpu", "off");
    double run1 = -1.0, run2 = -1.0, later = -1.0;
#ifdef CROSSRT_HAS_ISPC
    std::vector<double> firsts, seconds;
    for (int program = 0; program < 3; ++program)
    {
      std::filesystem::remove(memory);
      firsts.push_back(ChildMs(self, "lbvh_ispc", path, memory));
      seconds.push_back(ChildMs(self, "lbvh_ispc", path, memory));
    }
    run1 = MedianOf(firsts);
    run2 = MedianOf(seconds);
    later = median("lbvh_ispc", memory);  // the third program's runs 3 on
    if (*std::min_element(firsts.begin(), firsts.end()) < 0.0 || *std::min_element(seconds.begin(), seconds.end()) < 0.0) run1 = run2 = later = -1.0;
#endif
    if (embree < 0.0 || cpu < 0.0)
    {
      std::printf("| %-24s | a child failed\n", name);
      status = 1;
      continue;
    }
    auto cell = [&](double ms) {
      char text[32];
      if (ms < 0.0) return std::string("n/a");
      std::snprintf(text, sizeof text, "%.2f (%.2fx)", ms, ms / cpu);
      return std::string(text);
    };
    std::printf("| %-24s | %9zu | %10.2f | %8.2f | %19s | %19s | %19s |\n", name, triangles, embree, cpu, cell(run1).c_str(), cell(run2).c_str(),
                cell(later).c_str());
    if (csv)
      std::fprintf(csv, "\"%s\",%s,%s,%zu,%.4f,%.4f,%.4f,%.4f,%.4f\n", CpuModel().c_str(), crossrt::IspcTargetInUse().c_str(), name, triangles, embree, cpu,
                   run1, run2, later);
  }
  std::filesystem::remove(memory);
  if (!csv || std::fclose(csv) != 0) status = 1;
  return status;
}
