// Shared by the benchmarks: how a time is measured, and what it was measured on.
#pragma once
#include <crossrt/CpuParallel.h>
#include <crossrt/IspcSupport.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

// Median wall time in ms of `repeats` runs of `work`, after one warm-up run: first-use costs
// (pipeline creation, uploads, page faults) are not the steady state.
inline double MedianMs(int repeats, const std::function<void()>& work)
{
  work();
  std::vector<double> ms;
  for (int i = 0; i < repeats; ++i)
  {
    const auto t0 = std::chrono::steady_clock::now();
    work();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

// Wall time in seconds of one run of `work` (a first run, such as one that makes pipelines).
inline double Seconds(const std::function<void()>& work)
{
  const auto t0 = std::chrono::steady_clock::now();
  work();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The median of times measured elsewhere (interleaved rounds); 0 for none.
inline double MedianOf(std::vector<double> ms)
{
  if (ms.empty()) return 0.0;
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

// Wall times of several works measured in rounds, each round running every work once, after three
// warm-up rounds: a burst of load on a shared machine then slows them alike, and the ratio of two
// works taken round by round keeps its meaning. Three, as a program's first calls: by then an _ISPC
// class has run each kernel in SIMD lanes and once as its scalar loop, and keeps the faster
// (crossrt::LaneChoice). Returns each work's times, in ms.
inline std::vector<std::vector<double>> InterleavedMs(const std::vector<std::function<void()>>& works, int rounds)
{
  for (int warm = 0; warm < 3; ++warm)
    for (auto& work : works) work();
  std::vector<std::vector<double>> ms(works.size());
  for (int r = 0; r < rounds; ++r)
    for (size_t w = 0; w < works.size(); ++w)
    {
      const auto t0 = std::chrono::steady_clock::now();
      works[w]();
      ms[w].push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
  return ms;
}

// The q-quantile (0 <= q <= 1) of times measured elsewhere, the nearest measured time below it: 0.9
// for the 90th percentile, 1 for the slowest; 0 for none.
inline double QuantileOf(std::vector<double> ms, double q)
{
  if (ms.empty()) return 0.0;
  std::sort(ms.begin(), ms.end());
  return ms[size_t(q * double(ms.size() - 1))];
}

// The median over the rounds of a[r] / b[r] (times of InterleavedMs).
inline double PairedRatio(const std::vector<double>& a, const std::vector<double>& b)
{
  std::vector<double> r;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) r.push_back(a[i] / b[i]);
  return MedianOf(r);
}

// A CSV table's file, opened for writing after making its folder; null, with `program: cannot write
// PATH` on stderr, where it cannot be.
inline std::FILE* OpenCsv(const std::string& path, const char* program)
{
  std::error_code ignored;  // (a folder that cannot be made shows as the file that cannot be opened)
  if (std::filesystem::path(path).has_parent_path()) std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ignored);
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) std::fprintf(stderr, "%s: cannot write %s\n", program, path.c_str());
  return f;
}

// The CPU's model name (/proc/cpuinfo), which every table of speed figures prints, with its family
// and model numbers: a virtual machine's name can say only "AMD EPYC" for a Zen 4 (family 25) and a
// Zen 5 (family 26) alike.
inline std::string CpuModel()
{
  std::ifstream in("/proc/cpuinfo");
  std::string name = "unknown", family, model;
  auto value = [](const std::string& line) { return line.substr(line.find(':') + 2); };
  for (std::string line; std::getline(in, line) && line.find_first_not_of(" \t") != std::string::npos;) {
    if (line.rfind("model name", 0) == 0)
      name = value(line);
    else if (line.rfind("cpu family", 0) == 0)
      family = value(line);
    else if (line.rfind("model\t", 0) == 0 || line.rfind("model ", 0) == 0)
      model = value(line);
  }
  if (!family.empty() && !model.empty()) name += " (family " + family + ", model " + model + ")";
  return name;
}

// How the _ISPC classes' kernels pick between SIMD lanes and their scalar loop (CROSSRT_ISPC_LANES,
// crossrt::LaneChoice): "lanes or scalar, measured", "lanes always" or "scalar always".
inline const char* IspcLanes()
{
  switch (crossrt::LaneChoice::LanesMode())
  {
  case crossrt::LaneChoice::Mode::Always: return "lanes always";
  case crossrt::LaneChoice::Mode::Never: return "scalar always";
  default: return "lanes or scalar, measured";
  }
}

// N threads that keep a core each busy while started (from construction until Stop, and again after
// Start): `--load N`, the other work on a user's machine (an IDE, a browser, a build) beside a
// measurement. Each spins on arithmetic without sleeping, as `yes > /dev/null` does.
class BusyThreads
{
public:
  explicit BusyThreads(int n) : m_count(n) { Start(); }
  ~BusyThreads() { Stop(); }
  void Start()
  {
    if (!m_threads.empty()) return;
    m_stop = false;
    for (int i = 0; i < m_count; ++i)
      m_threads.emplace_back([this] {
        volatile unsigned x = 1;
        while (!m_stop.load(std::memory_order_relaxed))
          for (int k = 0; k < 4096; ++k) x = x * 1664525u + 1013904223u;
      });
  }
  void Stop()
  {
    m_stop = true;
    for (auto& t : m_threads) t.join();
    m_threads.clear();
  }
  int Count() const { return m_count; }

private:
  int m_count;
  std::atomic<bool> m_stop{false};
  std::vector<std::thread> m_threads;
};
