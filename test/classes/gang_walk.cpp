#include "gang_walk.h"

#include <algorithm>

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
    // Counted in it by the whole gang, one query at a time: the lanes share out the block's keys
    // (in a gang of one, the loop takes them one after another).
    uint32_t c = uint32_t(mine * kBlock);
    CRT_UNIFORM uint32_t waiting = crossrt::LaneBits(true);  // the lanes still on: not the NaN queries'
    while (waiting != 0u)
    {
      CRT_UNIFORM const int lane = __builtin_ctz(waiting);
      waiting = waiting & (waiting - 1u);
      CRT_UNIFORM const float itsQuery = crossrt::LaneValue(q, lane);
      CRT_UNIFORM const int itsBlock = crossrt::LaneValue(mine, lane);
      CRT_UNIFORM const int end = itsBlock < blocks ? (itsBlock + 1) * kBlock : int(m_keys.size());  // the last block takes the tail
      CRT_UNIFORM uint32_t inBlock = 0u;
      for (int first = itsBlock * kBlock; first < end; first += crossrt::GangSize())
      {
        const int k = first + crossrt::LaneIndex();
        inBlock = inBlock + uint32_t(__builtin_popcount(crossrt::LaneBits(k < end && AtOrBelow(m_keys[std::min(k, end - 1)], itsQuery) != 0u)));
      }
      c = crossrt::LaneIndex() == lane ? c + inBlock : c;
    }
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

void KeyCounter::CountQuarters(int n, const float* queries, uint32_t* counts) { kernel1D_CountQuarters(n, queries, counts); }

void KeyCounter::kernel1D_CountQuarters(int n, const float* queries, uint32_t* counts)
{
  for (int i = 0; i < n; i++)
  {
    const float q = queries[i];
    if (!(q == q))
    {
      counts[i] = kNoCount;
      continue;
    }
    uint32_t c = 0u;
    if (crossrt::GangSize() >= 4 && crossrt::AllLanesOn())
    {
      // A quad of lanes per query, each lane a key: the quad takes its lanes' queries in turn. (The
      // keys from a local copy: BVHScene's traversal reads a member's components, in memory.)
      const LiteMath::float4 quarters = m_quarters;
      const int quadStart = crossrt::LaneIndex() - crossrt::LaneIndex() % 4;
      for (int k = 0; k < 4; ++k)
      {
        const float itsQuery = crossrt::FromLane(q, quadStart + k);  // the query of the quad's lane k
        CRT_UNIFORM const uint32_t bits = crossrt::LaneBits(crossrt::LaneOfQuad(quarters) <= itsQuery);
        const uint32_t inQuad = uint32_t(__builtin_popcount((bits >> uint32_t(quadStart)) & 15u));
        c = crossrt::LaneIndex() == quadStart + k ? inQuad : c;
      }
    }
    else
    {
      // The gang's lanes share out each query's four keys, one query at a time (one after another in
      // a gang of one).
      CRT_UNIFORM uint32_t waiting = crossrt::LaneBits(true);
      while (waiting != 0u)
      {
        CRT_UNIFORM const int lane = __builtin_ctz(waiting);
        waiting = waiting & (waiting - 1u);
        CRT_UNIFORM const float itsQuery = crossrt::LaneValue(q, lane);
        CRT_UNIFORM uint32_t inQuarters = 0u;
        for (int first = 0; first < 4; first += crossrt::GangSize())
          inQuarters = inQuarters + uint32_t(__builtin_popcount(
                                        crossrt::LaneBits(first + crossrt::LaneIndex() < 4 && crossrt::LaneOf(m_quarters, first) <= itsQuery)));
        c = crossrt::LaneIndex() == lane ? inQuarters : c;
      }
    }
    counts[i] = c;
  }
}
