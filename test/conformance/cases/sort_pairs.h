// std::sort of a member vector of pairs with a comparator lambda on one field, after a kernel fills it.
#pragma once
#include "LiteMath.h"
#include <algorithm>
#include <cstdint>
#include <vector>
using LiteMath::uint2;

class SortPairs
{
public:
  SortPairs() : m_pairs(1000) {}
  virtual void MakeAndSort(uint32_t a_seed, uint2* a_out [[size("1000")]]);
  virtual void CommitDeviceData() {}
  std::vector<uint2> m_pairs;

protected:
  void kernel1D_Make(uint32_t n, uint32_t a_seed);
  void kernel1D_Copy(uint32_t n, uint2* a_out);
};
