#include "first_thread.h"

#include <algorithm>

using LiteMath::float2;
using LiteMath::float3;

// The slab's extent along the point's diagonal, or 0 where it misses (a helper taking the box's
// corners as const arrays, as kernel_slicer's RayBoxIntersectionLite takes them).
static float Extent(const float3 p, const float lo[3], const float hi[3])
{
  const float a = LiteMath::max(lo[0] - p.x, lo[1] - p.y);
  const float b = LiteMath::min(hi[0] - p.x, hi[2] - p.z);
  return b > a ? b - a : 0.0f;
}

FirstThread::FirstThread() : m_firsts(4, -1.0f)
{
  m_slabs.push_back(Slab{{-1.0f, -2.0f, -3.0f}, {2.0f, 3.0f, 4.0f}});
  m_slabs.push_back(Slab{{0.5f, 0.25f, 0.0f}, {1.5f, 1.0f, 2.0f}});
}

void FirstThread::Run(int n, const float* a_in, float* a_out) { kernel1D_Run(n, a_in, a_out); }

void FirstThread::kernel1D_Run(int n, const float* a_in, float* a_out)
{
  for (int i = 0; i < n; i++)
  {
    const int numSamples = 16;
    const float3 p = float3(a_in[i], 0.5f * a_in[i], -a_in[i]);
    float sum = 0.0f;
    for (int s = 0; s < numSamples; s++)
    {
      const Slab slab = m_slabs[s % 2];
      sum += Extent(p + float3(0.01f * float(s)), slab.lo, slab.hi);
    }
    float* mine = a_out + i;  // a row pointer whose offset differs per thread, at a constant index
    if (i >= 4)
      mine[0] = sum * (1.0f / float(numSamples));
    if (i == 1)
    {
      float* tail = a_out + 2;  // one shared by every thread
      tail[0] = a_in[1] * 3.0f;
      tail[1] += a_in[1];
    }
    if (i == 0)
    {
      const float2 v = float2(a_in[0] + 1.0f, a_in[0] * 2.0f);
      a_out[0] = v.x;
      a_out[1] += v.y;
      m_firsts[0] = v.x * v.y;
      m_firsts[3] = float(numSamples) + v.y;
      m_firsts[2] += std::min(v.x, 0.5f * v.y);  // (std::min's references: a statement with cleanups)
    }
  }
}
