// LiteMath's ReduceAdd family: per-thread partial sums into a member vector, set up and completed
// by the control function (kernel_slicer's 045_reduce_add).
#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <vector>
using LiteMath::ReduceAdd;
using LiteMath::ReduceAddComplete;
using LiteMath::ReduceAddInit;

class AccumGrid
{
public:
  AccumGrid() : m_accum(8) {}
  virtual void Accumulate(uint32_t n, const float* a_values [[size("n")]]);
  virtual void CommitDeviceData() {}
  std::vector<float> m_accum;

protected:
  void kernel1D_Accumulate(uint32_t n, const float* a_values);
};
