#include "TexturedHits.h"

using LiteMath::float2;
using LiteMath::float4;

void TexturedHits::Shade(int n, const float4* posAndNear, const float4* dirAndFar, float4* colors)
{
  kernel1D_Shade(n, posAndNear, dirAndFar, colors);
}

void TexturedHits::kernel1D_Shade(int n, const float4* posAndNear, const float4* dirAndFar, float4* colors)
{
  for (int i = 0; i < n; ++i)
  {
    const CRT_Hit hit = m_pAccelStruct->RayQuery_NearestHit(posAndNear[i], dirAndFar[i]);
    if (hit.primId == 0xFFFFFFFFu)
      colors[i] = float4(0.0f);
    else
      colors[i] = m_meshTextures[hit.geomId % uint32_t(m_meshTextures.size())].sample(float2(hit.coords[0], hit.coords[1]));
  }
}
