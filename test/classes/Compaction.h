// Stream compaction and prefix sums: kernels around std::exclusive_scan / std::inclusive_scan,
// std::fill and memcpy in control functions (test/equivalence/test_scan.cpp).
#pragma once
#include <cstdint>
#include <vector>

class Compaction
{
public:
  explicit Compaction(int capacity) : m_keep(capacity), m_slot(capacity), m_marks(capacity) {}
  virtual ~Compaction() = default;

  // Writes the positive values of `values`, in order, to the front of `out`; returns the count in m_kept.
  virtual void Compact(int n, [[crossrt::size("n")]] const float* values, [[crossrt::size("n")]] float* out);
  // prefix[i] = values[0] + ... + values[i]; copy = values; m_marks filled with 7.
  virtual void PrefixSum(int n, [[crossrt::size("n")]] const float* values, [[crossrt::size("n")]] float* prefix,
                         [[crossrt::size("n")]] float* copy);
  // Sorts the first n elements of m_slot and all of m_keep (radix sort on the GPU).
  virtual void SortSlots(int n);
  virtual void CommitDeviceData() {}

  uint32_t m_kept = 0;
  std::vector<uint32_t> m_keep, m_slot;
  std::vector<int> m_marks;

protected:
  void kernel1D_Mark(int n, const float* values, uint32_t* keep);
  void kernel1D_Scatter(int n, const float* values, const uint32_t* keep, const uint32_t* slot, float* out);
};
