#include "FlatShading.h"

void FlatShading::Shade(int n, const float4* normals, const uint32_t* materialIds, float4* colors)
{
  kernel1D_Shade(n, normals, materialIds, colors);
}

void FlatShading::kernel1D_Shade(int n, const float4* normals, const uint32_t* materialIds, float4* colors)
{
  for (int i = 0; i < n; ++i)
  {
    const float3 color = m_materials[materialIds[i]]->Shade(LiteMath::to_float3(normals[i]), m_toLight);
    colors[i] = LiteMath::to_float4(color, m_materials[materialIds[i]]->Opacity());
  }
}
