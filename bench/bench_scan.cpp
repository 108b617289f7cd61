// Benchmark: the GPU exclusive scan and radix sort that std::exclusive_scan and std::sort in a
// control function become, against the standard library on one CPU core, for 2^10 .. 2^22
// elements and sizes that are not powers of two. Keys/s; the GPU figure is the GPU time of the recorded scan (timestamps),
// medians of 5 after a warm-up, all measured in this run.
#include <crossrt/VulkanRuntime.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

int main()
{
  auto ctx = crossrt::VulkanContext::CreateDefault();
  crossrt::Scanner scanner(ctx);
  crossrt::GpuTimer timer(ctx);
  std::printf("device: %s\n\n| %10s | %14s | %14s | %8s |\n|%s|\n", ctx->DeviceName().c_str(), "elements", "CPU Mkeys/s",
              "GPU Mkeys/s", "GPU/CPU", std::string(58, '-').c_str());
  for (uint32_t n : {1u << 10, 1000u, 1u << 14, 1u << 16, 100003u, 1u << 18, 1u << 20, 3000017u, 1u << 22})
  {
    std::vector<uint32_t> in(n), out(n), gpuOut(n);
    for (uint32_t i = 0; i < n; ++i) in[i] = (i * 2654435761u) >> 28;
    crossrt::Buffer a(ctx, 4ull * n), b(ctx, 4ull * n);
    a.Upload(in.data(), 4ull * n);
    std::vector<double> cpu, gpu;
    for (int rep = 0; rep < 6; ++rep)
    {
      auto t0 = std::chrono::steady_clock::now();
      std::exclusive_scan(in.begin(), in.end(), out.begin(), 0u);
      cpu.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      VkCommandBuffer cmd = ctx->BeginOneShot();
      timer.Reset(cmd);
      timer.Begin(cmd, "scan");
      scanner.RecordCmd(cmd, a.View(), b.View(), n, false, crossrt::ScanType::Uint);
      timer.End(cmd, "scan");
      ctx->SubmitAndWait(cmd);
      timer.Collect();
      gpu.push_back(timer.LastMs("scan"));
    }
    b.Download(gpuOut.data(), 4ull * n);
    if (gpuOut != out)
    {
      std::printf("MISMATCH at n = %u\n", n);
      return 1;
    }
    std::sort(cpu.begin() + 1, cpu.end());  // the first run is the warm-up
    std::sort(gpu.begin() + 1, gpu.end());
    const double cpuMs = cpu[3], gpuMs = gpu[3];
    std::printf("| %10u | %14.1f | %14.1f | %7.2fx |\n", n, n / cpuMs / 1e3, n / gpuMs / 1e3, cpuMs / gpuMs);
  }

  // std::sort of uint32_t keys against the GPU radix sort.
  crossrt::RadixSorter sorter(ctx);
  std::printf("\n| %10s | %14s | %14s | %8s |\n|%s|\n", "sort keys", "CPU Mkeys/s", "GPU Mkeys/s", "GPU/CPU",
              std::string(58, '-').c_str());
  for (uint32_t n : {1u << 10, 1000u, 1u << 14, 100003u, 1u << 18, 1u << 20, 3000017u, 1u << 22})
  {
    std::vector<uint32_t> keys(n), sorted, gpuOut(n);
    uint32_t state = 12345u;
    for (auto& k : keys) k = (state = state * 1664525u + 1013904223u);
    crossrt::Buffer a(ctx, 4ull * n);
    std::vector<double> cpu, gpu;
    for (int rep = 0; rep < 6; ++rep)
    {
      sorted = keys;
      auto t0 = std::chrono::steady_clock::now();
      std::sort(sorted.begin(), sorted.end());
      cpu.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      a.Upload(keys.data(), 4ull * n);
      VkCommandBuffer cmd = ctx->BeginOneShot();
      timer.Reset(cmd);
      timer.Begin(cmd, "sort");
      sorter.RecordCmd(cmd, a.View(), {}, n);
      timer.End(cmd, "sort");
      ctx->SubmitAndWait(cmd);
      timer.Collect();
      gpu.push_back(timer.LastMs("sort"));
    }
    a.Download(gpuOut.data(), 4ull * n);
    if (gpuOut != sorted)
    {
      std::printf("MISMATCH in sort at n = %u\n", n);
      return 1;
    }
    std::sort(cpu.begin() + 1, cpu.end());
    std::sort(gpu.begin() + 1, gpu.end());
    std::printf("| %10u | %14.1f | %14.1f | %7.2fx |\n", n, n / cpu[3] / 1e3, n / gpu[3] / 1e3, cpu[3] / gpu[3]);
  }
  return 0;
}
