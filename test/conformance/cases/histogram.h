// LiteMath's InterlockedAdd on elements of a member vector and of an output pointer.
#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <vector>
using LiteMath::InterlockedAdd;

class Histogram
{
public:
  Histogram() : m_bins(16, 0u) {}
  virtual void Count(int n, const float* a_values [[size("n")]], int* a_sums [[size("4")]]);
  virtual void CommitDeviceData() {}
  std::vector<uint32_t> m_bins;
  float m_weight = 0.0f;

protected:
  void kernel1D_Count(int n, const float* a_values, int* a_sums);
};
