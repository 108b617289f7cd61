#include "CallableShading.h"

void CallableShading::Render(int width, int height, const float4* normals, const uint32_t* materialIds, float4* colors)
{
  kernel2D_Render(width, height, normals, materialIds, colors);
}

void CallableShading::kernel2D_Render(int width, int height, const float4* normals, const uint32_t* materialIds, float4* colors)
{
  for (int y = 0; y < height; ++y)
  {
    for (int x = 0; x < width; ++x)
    {
      const int i = y * width + x;
      float3 color = m_materials[materialIds[i]]->Shade(LiteMath::to_float3(normals[i]), m_toLight);
      m_materials[materialIds[i]]->Attenuate(color, m_distanceStep * float(x + y));
      colors[i] = LiteMath::to_float4(color, m_materials[materialIds[i]]->Opacity());
    }
  }
}
