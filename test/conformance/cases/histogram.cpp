#include "histogram.h"

void Histogram::Count(int n, const float* a_values, int* a_sums) { kernel1D_Count(n, a_values, a_sums); }

void Histogram::kernel1D_Count(int n, const float* a_values, int* a_sums)
{
  for (int i = 0; i < n; i++)
  {
    const float v = a_values[i];
    const uint32_t bin = uint32_t(v * 16.0f) % 16u;
    InterlockedAdd(m_bins[bin], 1u);
    InterlockedAdd(a_sums[i % 4], i);
    InterlockedAdd(m_bins[15], 1u);  // one bin for every thread, the same value: added once per thread (found by the differential tester)
  }
}
