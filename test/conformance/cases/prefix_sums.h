// std::inclusive_scan with an operator and an initial value, and std::exclusive_scan, in a control
// function (kernel_slicer's 023_prefix_summ).
#pragma once
#include "LiteMath.h"

class PrefixSums
{
public:
  virtual void Scan(const int* a_data [[size("a_size")]], unsigned a_size, int* a_outExc [[size("a_size")]], int* a_outInc [[size("a_size")]]);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Square(int* a_data, unsigned a_size);
};
