#include "gang_walk.h"

static uint32_t AtOrBelow(float key, float q) { return key <= q ? 1u : 0u; }

void KeyCounter::Count(int n, const float* queries, uint32_t* counts)
{
  m_total = 0;
  kernel1D_Count(n, queries, counts);
  m_mean = n > 0 ? float(m_total) / float(n) : 0.0f;
}

void KeyCounter::kernel1D_Count(int n, const float* queries, uint32_t* counts)
{
  for (int i = 0; i < n; i++)
  {
    const float q = queries[i];
    if (!(q == q))  // a NaN query is no count; its lane leaves, and the gang walks on without it
    {
      counts[i] = kNoCount;
      continue;
    }
    CRT_UNIFORM const int blocks = int(m_keys.size()) / kBlock;
    // Together: past each block whose last key some query of the gang is at or beyond.
    CRT_UNIFORM int block = 0;
    while (block < blocks && crossrt::AnyLane(m_keys[block * kBlock + kBlock - 1] <= q))
      block = block + 1;
    // Alone: back to the first block whose last key is beyond q (every key before it is <= q).
    int mine = block;
    while (mine > 0 && m_keys[mine * kBlock - 1] > q)
      mine = mine - 1;
    uint32_t c = uint32_t(mine * kBlock);
    const int end = mine < blocks ? (mine + 1) * kBlock : int(m_keys.size());  // the last block takes the tail
    for (int k = mine * kBlock; k < end; k++)
      c += AtOrBelow(m_keys[k], q);
    // Every lane on (a full gang without a NaN query): ISPC runs this branch unmasked. Where a lane
    // is off, the else: an unmasked write there would give a NaN query a count instead of kNoCount.
    if (crossrt::AllLanesOn())
    {
      counts[i] = c;
      m_total += c;
    }
    else
    {
      counts[i] = c;
      m_total += c;
    }
  }
}
