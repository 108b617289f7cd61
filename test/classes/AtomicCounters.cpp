#include "AtomicCounters.h"

void AtomicCounters::Count(int n, const uint32_t* keys, int32_t* perResidue)
{
  m_smallest = 0xFFFFFFFFu;
  m_largest = 0u;
  kernel1D_ClearBins(int(m_bins.size()));
  kernel1D_Count(n, keys, perResidue);
}

void AtomicCounters::kernel1D_ClearBins(int bins)
{
  for (int b = 0; b < bins; b++)
  {
    m_bins[b] = 0u;
    m_owner[b] = kNobody;
    m_last[b] = kNobody;
    if (b < 3)
      m_masks[b] = b == 1 ? 0xFFFFFFFFu : 0u;  // the identities of OR, AND, XOR
  }
}

void AtomicCounters::kernel1D_Count(int n, const uint32_t* keys, int32_t* perResidue)
{
  for (int i = 0; i < n; i++)
  {
    const uint32_t key = keys[i];
    const uint32_t bin = BinOf(key);
    crossrt::AtomicAdd(m_bins[bin], 1u);
    crossrt::AtomicCompareExchange(m_owner[bin], kNobody, uint32_t(i));
    crossrt::AtomicExchange(m_last[bin], uint32_t(i));
    crossrt::AtomicOr(m_masks[0], key);
    crossrt::AtomicAnd(m_masks[1], key);
    crossrt::AtomicXor(m_masks[2], key);
    crossrt::AtomicMin(m_smallest, key);
    crossrt::AtomicMax(m_largest, key);
    crossrt::AtomicAdd(perResidue[key % 4u], 1);
  }
}

void AtomicCounters::SumTree(int leafCount, const uint32_t* values)
{
  kernel1D_ClearArrivals(leafCount - 1);
  kernel1D_Climb(leafCount, values);
}

void AtomicCounters::kernel1D_ClearArrivals(int inner)
{
  for (int k = 0; k < inner; k++)
    m_arrivals[k] = 0u;
}

void AtomicCounters::kernel1D_Climb(int leafCount, const uint32_t* values)
{
  for (int leaf = 0; leaf < leafCount; leaf++)
  {
    uint32_t node = uint32_t(leafCount - 1 + leaf);
    m_treeSums[node] = values[leaf];
    while (node != 0u)
    {
      const uint32_t parent = (node - 1u) / 2u;
      // The first child to arrive stops. The second sees its sibling's sum: the sibling wrote it
      // before its own atomic on the same counter.
      if (crossrt::AtomicAdd(m_arrivals[parent], 1u) == 0u)
        break;
      m_treeSums[parent] = m_treeSums[2u * parent + 1u] + m_treeSums[2u * parent + 2u];
      node = parent;
    }
  }
}

void AtomicCounters::Splat(int n, int cells, const LiteMath::float4* points, float* sums)
{
  kernel1D_Splat(n, cells, points, sums);
}

void AtomicCounters::kernel1D_Splat(int n, int cells, const LiteMath::float4* points, float* sums)
{
  for (int i = 0; i < n; i++)
  {
    const int cell = i % cells;
    LiteMath::ReduceAdd(m_weights, cell, points[i].w);  // skips an infinite or NaN weight
    LiteMath::InterlockedAdd3f(sums, 3 * cell, LiteMath::to_float3(points[i]));
  }
}
