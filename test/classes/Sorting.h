// std::sort in control functions with the key types and comparators the GPU radix sort takes:
// key/value pairs ordered by one field (LBVH's Morton codes), records of several words ordered
// by a float or int field either way, std::greater, and plain floats (test/equivalence/test_sort.cpp).
#pragma once
#include "LiteMath.h"

#include <cstdint>
#include <vector>

struct Sample
{
  float weight;
  uint32_t id;
  int bucket;
};

class Sorting
{
public:
  explicit Sorting(int capacity) : m_codes(capacity), m_samples(capacity), m_values(capacity), m_floats(capacity) {}
  virtual ~Sorting() = default;

  // m_codes[i] = (hash of i, i) for i < n, then sorted by the hash: the LBVH pattern.
  virtual void SortCodes(int n);
  // m_samples by weight, largest first; then by bucket, smallest first.
  virtual void SortSamplesByWeight();
  virtual void SortSamplesByBucket();
  // m_values largest first (std::greater); m_floats ascending (no comparator).
  virtual void SortValues();
  virtual void CommitDeviceData() {}

  std::vector<LiteMath::uint2> m_codes;
  std::vector<Sample> m_samples;
  std::vector<int> m_values;
  std::vector<float> m_floats;

protected:
  void kernel1D_MakeCodes(int n, LiteMath::uint2* codes);
};
