// Shared by the benchmarks: how a time is measured.
#pragma once
#include <algorithm>
#include <chrono>
#include <functional>
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

// The median of times measured elsewhere (interleaved rounds); 0 for none.
inline double MedianOf(std::vector<double> ms)
{
  if (ms.empty()) return 0.0;
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}
