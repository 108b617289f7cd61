#include "Appending.h"

#include <algorithm>
#include <cmath>
#include <functional>

namespace demo::appends
{

void Appending::Select(int n, float threshold, const float* values, float* out)
{
  m_positive.clear();
  m_large.clear();
  kernel1D_FindPositive(n, values);
  kernel1D_FindLarge(threshold, values);
  kernel1D_Write(out);
}

void Appending::SelectSorted(int n, float threshold, const float* values, float* ranks)
{
  m_positive.clear();
  m_large.clear();
  kernel1D_FindPositive(n, values);
  std::sort(m_positive.begin(), m_positive.end(), std::greater<uint32_t>());
  kernel1D_FindLarge(threshold, values);
  std::sort(m_large.begin(), m_large.end(), [](const Candidate& a, const Candidate& b) { return a.value < b.value; });
  kernel1D_Rank(ranks);
}

void Appending::Collect(int n, const float* values)
{
  kernel1D_FindNegative(n, values);
}

void Appending::Classify(int n, const float* values)
{
  m_small.clear();
  m_tagged.clear();
  kernel1D_FindSmall(n, values);
  for (int i = 0; i < n; ++i)
    kernel_Tag(i, values);
}

void Appending::kernel1D_FindPositive(int n, const float* values)
{
  for (int i = 0; i < n; ++i)
    if (values[i] > 0.0f)
      m_positive.push_back(uint32_t(i));
}

void Appending::kernel1D_FindLarge(float threshold, const float* values)
{
  for (uint32_t i = 0; i < m_positive.size(); ++i)
  {
    const uint32_t index = m_positive[i];
    if (values[index] > threshold)
      m_large.push_back(Candidate{index, 2.0f * values[index]});
  }
}

void Appending::kernel1D_Write(float* out)
{
  for (uint32_t i = 0; i < m_large.size(); ++i)
    out[m_large[i].index] = m_large[i].value;
}

void Appending::kernel1D_Rank(float* ranks)
{
  for (uint32_t i = 0; i < m_large.size(); ++i)
    ranks[m_large[i].index] = float(i);
}

void Appending::Room(int n, uint32_t* room)
{
  kernel1D_Room(n, room);
}

void Appending::kernel1D_Room(int n, uint32_t* room)
{
  for (int i = 0; i < n; ++i)
    room[i] = uint32_t(m_negative.capacity() - m_negative.size());
}

void Appending::kernel1D_FindNegative(int n, const float* values)
{
  for (int i = 0; i < n; ++i)
    if (values[i] < 0.0f)
      m_negative.push_back(uint32_t(i));
}

void Appending::kernel1D_FindSmall(int n, const float* values)
{
  for (int i = 0; i < n; ++i)
    NoteSmall(uint32_t(i), values[i]);
}

uint32_t Appending::NoteSmall(uint32_t i, float value, float limit)
{
  if (!NoteSmall(value, limit))
    return 0;
  Append(i);
  return 1;
}

void Appending::kernel_Tag(int tid, const float* values)
{
  if (values[tid] > 0.9f)
    m_tagged.push_back(Candidate{uint32_t(tid), values[tid]});
}
}  // namespace demo::appends
