// Elements of member arrays reduced in a kernel loop: nine colour moments at constant indices, as
// kernel_slicer's spherical harmonics write them (m_moments[0] += c; m_moments[1] += c * d.y; ...),
// a histogram at an index each thread computes (m_bins[bin] += 1), the least value of each of two
// classes (m_least[k] = std::min(m_least[k], v)), and a whole member reduced beside them; and the
// same into local arrays declared before the loop, whose totals the statements after it write out.
// A second kernel reduces arrays of other types: uint with std::max, int2 and uint3 sums (uint3, as
// float3, is 16 bytes an element on the GPU), float4 with LiteMath's min.
#pragma once
#include "LiteMath.h"

#include <cstdint>

class ElementTotals
{
public:
  static constexpr int kMoments = 9;
  static constexpr int kBins = 6;

  virtual ~ElementTotals() = default;
  virtual void Measure(int n, const LiteMath::float4* a_samples [[size("n")]]);
  virtual void CommitDeviceData() {}

  LiteMath::float3 m_moments[kMoments];
  float m_bins[kBins];
  int m_least[2];
  int m_count = 0;
  float m_spread[3];  // from local arrays: the mean of x per third of the samples, then the largest y of each half
  float m_highest[2];
  uint32_t m_top[3];
  LiteMath::int2 m_pairs[2];
  LiteMath::uint3 m_counts[2];
  LiteMath::float4 m_low[2];

protected:
  virtual void kernel1D_Measure(int n, const LiteMath::float4* a_samples);
  virtual void kernel1D_Extremes(int n, const LiteMath::float4* a_samples);
};
