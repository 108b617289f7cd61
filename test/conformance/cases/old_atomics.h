// The older spellings of LiteMath's atomics in kernel_slicer's samples: atomicAdd(a_out[i], v) on
// an output pointer, InterlockedAdd3f(array, offset, float3) into a float array.
#pragma once
#include "LiteMath.h"
#include <cstdint>
using LiteMath::float3;

class OldAtomics
{
public:
  OldAtomics() {}
  virtual void Scatter(uint32_t a_threads, int32_t* a_counts [[size("a_bins")]], float* a_sums [[size("a_bins * 4")]], uint32_t a_bins);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Scatter(uint32_t a_threads, int32_t* a_counts, float* a_sums, uint32_t a_bins);
};
