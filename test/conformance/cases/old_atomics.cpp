#include "old_atomics.h"

using LiteMath::atomicAdd;
using LiteMath::InterlockedAdd3f;

void OldAtomics::Scatter(uint32_t a_threads, int32_t* a_counts, float* a_sums, uint32_t a_bins)
{
  kernel1D_Scatter(a_threads, a_counts, a_sums, a_bins);
}

void OldAtomics::kernel1D_Scatter(uint32_t a_threads, int32_t* a_counts, float* a_sums, uint32_t a_bins)
{
  #pragma omp parallel for
  for (uint32_t i = 0; i < a_threads; i++)
  {
    const uint32_t bin = (i * 7u) % a_bins;
    atomicAdd(a_counts[bin], int(i % 3));
    InterlockedAdd3f(a_sums, int(bin * 4), float3(1.0f, 0.5f, float(i % 4)));
  }
}
