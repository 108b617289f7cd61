#include "Sorting.h"

#include <algorithm>
#include <functional>

using LiteMath::uint2;

void Sorting::SortCodes(int n)
{
  kernel1D_MakeCodes(n, m_codes.data());
  std::sort(m_codes.begin(), m_codes.begin() + n, [](uint2 a, uint2 b) { return a.x < b.x; });
}

void Sorting::SortSamplesByWeight()
{
  std::sort(m_samples.begin(), m_samples.end(), [](const Sample& a, const Sample& b) { return a.weight > b.weight; });
}

void Sorting::SortSamplesByBucket()
{
  std::sort(m_samples.begin(), m_samples.end(), [](Sample a, Sample b) { return b.bucket > a.bucket; });
}

void Sorting::SortValues()
{
  std::sort(m_values.begin(), m_values.end(), std::greater<int>());
  std::sort(m_floats.begin(), m_floats.end());
}

void Sorting::kernel1D_MakeCodes(int n, uint2* codes)
{
  for (int i = 0; i < n; i++)
  {
    uint32_t h = uint32_t(i) * 2654435761u;
    h ^= h >> 13;
    codes[i] = uint2(h & 0xFFFFu, uint32_t(i));  // 16-bit codes: many repeat
  }
}
