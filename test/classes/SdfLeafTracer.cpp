#include "SdfLeafTracer.h"

void SdfLeafTracer::Trace(int n, const LiteMath::float4* origins, const LiteMath::float4* dirs, CRT_Hit* hits) { kernel1D_Trace(n, origins, dirs, hits); }

void SdfLeafTracer::kernel1D_Trace(int n, const LiteMath::float4* origins, const LiteMath::float4* dirs, CRT_Hit* hits)
{
  for (int i = 0; i < n; ++i)
    hits[i] = m_scene->RayQuery_NearestHit(origins[i], dirs[i]);
}
