#include "TexturedMaterials.h"

using LiteMath::float2;
using LiteMath::float4;
using LiteMath::int2;

void TexturedMaterials::Shade(int n, const uint32_t* texIds, const float2* uvs, float4* colors, float* heights, float4* texels)
{
  kernel1D_Shade(n, texIds, uvs, colors, heights, texels);
}

float4 TexturedMaterials::Albedo(uint32_t a_texId, float2 a_uv) const { return m_albedo[a_texId].sample(a_uv); }

void TexturedMaterials::kernel1D_Shade(int n, const uint32_t* texIds, const float2* uvs, float4* colors, float* heights, float4* texels)
{
  for (int i = 0; i < n; ++i)
  {
    const uint32_t id = texIds[i] % uint32_t(m_albedo.size());
    colors[i] = Albedo(id, uvs[i]);
    const uint32_t bump = texIds[i] % uint32_t(m_bumps.size());
    heights[i] = m_bumps[bump].sample(uvs[i]) + float(m_bumps[bump].width()) + m_bumps_sample + m_bumps_texel + m_bumps_width + m_bumps_info + m_bumps_texels;
    const int2 p = int2(i % int(m_albedo[0].width()), (i / 3) % int(m_albedo[0].height()));
    texels[i] = m_albedo[0][p];
  }
}
