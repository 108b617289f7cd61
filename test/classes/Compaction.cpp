#include "Compaction.h"

#include <algorithm>
#include <cstring>
#include <numeric>

void Compaction::Compact(int n, const float* values, float* out)
{
  kernel1D_Mark(n, values, m_keep.data());
  std::exclusive_scan(m_keep.begin(), m_keep.begin() + n, m_slot.begin(), 0u);
  kernel1D_Scatter(n, values, m_keep.data(), m_slot.data(), out);
}

void Compaction::PrefixSum(int n, const float* values, float* prefix, float* copy)
{
  std::inclusive_scan(values, values + n, prefix);
  std::memcpy(copy, values, sizeof(float) * n);
  std::fill(m_marks.begin(), m_marks.end(), 7);
}

void Compaction::kernel1D_Mark(int n, const float* values, uint32_t* keep)
{
  for (int i = 0; i < n; i++)
    keep[i] = values[i] > 0.0f ? 1u : 0u;
}

void Compaction::kernel1D_Scatter(int n, const float* values, const uint32_t* keep, const uint32_t* slot, float* out)
{
  for (int i = 0; i < n; i++)
  {
    if (keep[i] != 0u)
      out[slot[i]] = values[i];
    if (i == n - 1)
      m_kept += slot[i] + keep[i];
  }
}

void Compaction::SortSlots(int n)
{
  std::sort(m_slot.begin(), m_slot.begin() + n);
  std::sort(m_keep.begin(), m_keep.end(), [](uint32_t a, uint32_t b) { return a < b; });
}
