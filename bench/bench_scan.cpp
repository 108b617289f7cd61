// Benchmark: the GPU exclusive scan and radix sort that std::exclusive_scan and std::sort in a
// control function become, against the standard library on one CPU core, for 2^10 .. 2^22
// elements and sizes that are not powers of two. Keys/s; the GPU figure is the timestamp-measured
// GPU time of the recorded work; medians of 5 after a warm-up, all measured in this run. Every
// GPU result is compared with the CPU's. A last table prices the sort of an appended vector,
// whose count only the GPU has.
#include "CommandLine.h"

#include <crossrt/VulkanRuntime.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <numeric>
#include <string>
#include <vector>

namespace {

struct Timing { double cpuMs, gpuMs; };

// Runs `cpu` and the GPU work `record` records 6 times each; the first run is a warm-up.
Timing Measure(crossrt::VulkanContext& ctx, crossrt::GpuTimer& timer, const std::function<void()>& cpu,
               const std::function<void(VkCommandBuffer)>& record)
{
  std::vector<double> cpuMs, gpuMs;
  for (int rep = 0; rep < 6; ++rep)
  {
    auto t0 = std::chrono::steady_clock::now();
    cpu();
    cpuMs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    VkCommandBuffer cmd = ctx.BeginOneShot();
    timer.Reset(cmd);
    timer.Begin(cmd, "work");
    record(cmd);
    timer.End(cmd, "work");
    ctx.SubmitAndWait(cmd);
    timer.Collect();
    gpuMs.push_back(timer.LastMs("work"));
  }
  std::sort(cpuMs.begin() + 1, cpuMs.end());
  std::sort(gpuMs.begin() + 1, gpuMs.end());
  return {cpuMs[3], gpuMs[3]};
}

void Header(const char* what)
{
  std::printf("\n| %10s | %14s | %14s | %8s |\n|%s|\n", what, "CPU Mkeys/s", "GPU Mkeys/s", "GPU/CPU", std::string(58, '-').c_str());
}

void Row(uint32_t n, Timing t)
{
  std::printf("| %10u | %14.1f | %14.1f | %7.2fx |\n", n, n / t.cpuMs / 1e3, n / t.gpuMs / 1e3, t.cpuMs / t.gpuMs);
}

}  // namespace

int main(int argc, char** argv)
{
  crossrt::CommandLine app("bench_scan",
                           "The GPU exclusive scan and radix sort against the standard library on one core, 2^10 .. 2^22\n"
                           "elements; prints keys/s and ratios.");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  auto ctx = crossrt::VulkanContext::CreateDefault();
  crossrt::GpuTimer timer(ctx);
  std::printf("device: %s\n", ctx->DeviceName().c_str());

  crossrt::Scanner scanner(ctx);
  Header("scan");
  for (uint32_t n : {1u << 10, 1000u, 1u << 14, 1u << 16, 100003u, 1u << 18, 1u << 20, 3000017u, 1u << 22})
  {
    std::vector<uint32_t> in(n), out(n), gpuOut(n);
    for (uint32_t i = 0; i < n; ++i) in[i] = (i * 2654435761u) >> 28;
    crossrt::Buffer a(ctx, 4ull * n), b(ctx, 4ull * n);
    a.Upload(in.data(), 4ull * n);
    Timing t = Measure(*ctx, timer, [&] { std::exclusive_scan(in.begin(), in.end(), out.begin(), 0u); },
                       [&](VkCommandBuffer cmd) { scanner.RecordCmd(cmd, a.View(), b.View(), n, false, crossrt::ElementType::Uint); });
    b.Download(gpuOut.data(), 4ull * n);
    if (gpuOut != out)
    {
      std::printf("MISMATCH in scan at n = %u\n", n);
      return 1;
    }
    Row(n, t);
  }

  // Plain keys, then (key, index) pairs ordered by the key: LBVH's sort of Morton codes.
  crossrt::RadixSorter sorter(ctx);
  for (uint32_t words : {1u, 2u})
  {
    Header(words == 1 ? "sort keys" : "sort pairs");
    for (uint32_t n : {1u << 10, 1000u, 1u << 14, 100003u, 1u << 18, 1u << 20, 3000017u, 1u << 22})
    {
      std::vector<uint32_t> records(size_t(words) * n), sorted, gpuOut(records.size());
      uint32_t state = 12345u;
      for (uint32_t i = 0; i < n; ++i)
      {
        records[size_t(words) * i] = (state = state * 1664525u + 1013904223u);
        if (words == 2) records[2 * size_t(i) + 1] = i;
      }
      crossrt::Buffer a(ctx, 4ull * records.size());
      auto cpuSort = [&] {
        sorted = records;
        if (words == 1)
          std::sort(sorted.begin(), sorted.end());
        else
        {
          auto* pairs = reinterpret_cast<uint64_t*>(sorted.data());  // little-endian: key in the low word
          std::sort(pairs, pairs + n, [](uint64_t x, uint64_t y) { return uint32_t(x) < uint32_t(y); });
        }
      };
      Timing t = Measure(*ctx, timer, cpuSort, [&](VkCommandBuffer cmd) {
        a.Upload(records.data(), 4ull * records.size());  // before recording: the sort works in place
        sorter.RecordCmd(cmd, a.View(), n, crossrt::SortKey{words, 0, crossrt::ElementType::Uint, false});
      });
      a.Download(gpuOut.data(), 4ull * records.size());
      // The GPU sort is stable; std::sort need not be: compare with a stable sort of the input.
      std::vector<uint32_t> expected = records;
      auto* pairs = reinterpret_cast<uint64_t*>(expected.data());
      if (words == 1)
        std::stable_sort(expected.begin(), expected.end());
      else
        std::stable_sort(pairs, pairs + n, [](uint64_t x, uint64_t y) { return uint32_t(x) < uint32_t(y); });
      if (gpuOut != expected)
      {
        std::printf("MISMATCH in sort (%u words) at n = %u\n", words, n);
        return 1;
      }
      Row(n, t);
    }
  }

  // The sort of a vector kernels appended to: the count is a word on the GPU and the work is that
  // of the capacity (the vector's reserve()). Against the same n sorted with the count on the host.
  std::printf("\n| %10s | %10s | %16s | %16s | %9s |\n|%s|\n", "n", "capacity", "host count ms", "GPU count ms", "GPU/host",
              std::string(77, '-').c_str());
  for (uint32_t n : {100003u, 1u << 20})
    for (uint32_t capacity : {n, 2 * n})
    {
      std::vector<uint32_t> records(capacity), gpuOut(n);
      uint32_t state = 777u;
      for (auto& r : records) r = (state = state * 1664525u + 1013904223u);
      crossrt::Buffer a(ctx, 4ull * capacity), count(ctx, 16);
      count.Upload(&n, 4);
      const crossrt::SortKey key{1, 0, crossrt::ElementType::Uint, false};
      auto gpuMs = [&](bool countOnGpu) {
        return Measure(*ctx, timer, [] {}, [&](VkCommandBuffer cmd) {
                 a.Upload(records.data(), 4ull * capacity);
                 if (countOnGpu)
                   sorter.RecordCmd(cmd, a.View(), capacity, key, count.View(), 0);
                 else
                   sorter.RecordCmd(cmd, a.View(), n, key);
               }).gpuMs;
      };
      const double host = gpuMs(false), gpu = gpuMs(true);
      a.Download(gpuOut.data(), 4ull * n);
      std::vector<uint32_t> expected(records.begin(), records.begin() + n);
      std::sort(expected.begin(), expected.end());
      if (gpuOut != expected)
      {
        std::printf("MISMATCH in the sort with the count on the GPU at n = %u\n", n);
        return 1;
      }
      std::printf("| %10u | %10u | %16.2f | %16.2f | %8.2fx |\n", n, capacity, host, gpu, gpu / host);
    }
  return 0;
}
