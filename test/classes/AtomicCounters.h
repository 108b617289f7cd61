// Atomics in kernels (crossrt::Atomic*, Atomics.h): counters, minimum and maximum, bit masks,
// claims, and a bottom-up pass over a tree where the second child to arrive finishes its parent
// (the pattern of an LBVH refit), and LiteMath's float adds (ReduceAdd, InterlockedAdd3f). The results are compared on every backend in
// test/equivalence/test_atomics.cpp.
#pragma once
#include "Atomics.h"
#include "LiteMath.h"

#include <cstddef>
#include <cstdint>
#include <vector>

class AtomicCounters
{
public:
  static constexpr uint32_t kNobody = 0xFFFFFFFFu;  // m_owner of a bin no key fell into

  AtomicCounters(int binCount, int maxLeaves)
  {
    m_bins.resize(binCount);
    m_owner.resize(binCount);
    m_last.resize(binCount);
    m_masks.resize(3);
    m_treeSums.resize(2 * std::size_t(maxLeaves > 0 ? maxLeaves : 1) - 1);
    m_arrivals.resize(m_treeSums.size());
  }
  virtual ~AtomicCounters() = default;

  // Over keys[0, n): m_bins[b] counts the keys with key % bins == b; m_owner[b] is the index of
  // the first key to claim bin b and m_last[b] that of the last to pass it (both in any order);
  // m_masks = {OR, AND, XOR} of all keys; m_smallest and m_largest their extremes; and
  // perResidue[key % 4] (which the caller sets) grows by one per key.
  virtual void Count(int n, [[crossrt::size("n")]] const uint32_t* keys, [[crossrt::size("4")]] int32_t* perResidue);
  // A complete binary tree over `leafCount` leaves in heap order (node k has children 2k + 1 and
  // 2k + 2; the leaves are nodes leafCount - 1 and up): m_treeSums[k] = the sum of the values of
  // the leaves under k, computed from the leaves up in one pass.
  virtual void SumTree(int leafCount, [[crossrt::size("leafCount")]] const uint32_t* values);
  // Over points[0, n) (x, y, z, weight), each in cell i % cells: m_weights[c] (which the caller
  // sizes and sets) grows by the finite weights of cell c's points, and sums[3c, 3c + 3) by their
  // x, y and z (LiteMath's ReduceAdd and InterlockedAdd3f).
  virtual void Splat(int n, int cells, [[crossrt::size("n")]] const LiteMath::float4* points, [[crossrt::size("3 * cells")]] float* sums);
  virtual void CommitDeviceData() {}

  std::vector<uint32_t> m_bins, m_owner, m_last, m_masks;
  uint32_t m_smallest = 0, m_largest = 0;
  std::vector<uint32_t> m_treeSums, m_arrivals;
  std::vector<float> m_weights;

protected:
  void kernel1D_ClearBins(int bins);
  void kernel1D_Count(int n, const uint32_t* keys, int32_t* perResidue);
  void kernel1D_ClearArrivals(int inner);
  void kernel1D_Climb(int leafCount, const uint32_t* values);
  void kernel1D_Splat(int n, int cells, const LiteMath::float4* points, float* sums);
  uint32_t BinOf(uint32_t key) const { return key % uint32_t(m_bins.size()); }
};
