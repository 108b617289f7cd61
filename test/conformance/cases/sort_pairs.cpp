#include "sort_pairs.h"

void SortPairs::MakeAndSort(uint32_t a_seed, uint2* a_out)
{
  kernel1D_Make(uint32_t(m_pairs.size()), a_seed);
  std::sort(m_pairs.begin(), m_pairs.end(), [](uint2 a, uint2 b) { return a.x < b.x; });
  kernel1D_Copy(uint32_t(m_pairs.size()), a_out);
}

void SortPairs::kernel1D_Make(uint32_t n, uint32_t a_seed)
{
  for (uint32_t i = 0; i < n; i++)
    m_pairs[i] = uint2((i * 7919u + a_seed) % 1009u, i);  // distinct keys: std::sort need not keep ties in order
}

void SortPairs::kernel1D_Copy(uint32_t n, uint2* a_out)
{
  for (uint32_t i = 0; i < n; i++)
    a_out[i] = m_pairs[i];
}
