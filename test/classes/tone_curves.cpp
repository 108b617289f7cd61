#include "tone_curves.h"

using namespace LiteMath;

static float Luminance(float3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

void ToneMapper::Map(int n, const float4* hdr, float4* ldr)
{
  m_clipped = 0;
  kernel1D_Map(n, hdr, ldr);
  m_clippedShare = n > 0 ? float(m_clipped) / float(n) : 0.0f;
}

void ToneMapper::kernel1D_Map(int n, const float4* hdr, float4* ldr)
{
  for (int i = 0; i < n; i++)
  {
    float3 c = to_float3(hdr[i]) * m_exposure;
    if (m_clampNegative)
      c = max(c, float3(0.0f));
    if (Luminance(c) >= m_whitePoint)
      m_clipped += 1;
    float3 mapped = c;
    if (m_curve == ToneCurve::Reinhard)
      mapped = c * (float3(1.0f) + c / (m_whitePoint * m_whitePoint)) / (float3(1.0f) + c);
    else if (m_curve == ToneCurve::Aces)
      mapped = (c * (2.51f * c + float3(0.03f))) / (c * (2.43f * c + float3(0.59f)) + float3(0.14f));
    mapped = clamp(mapped, float3(0.0f), float3(1.0f));
    if (m_bands > 0)
      mapped = floor(mapped * float(m_bands)) / float(m_bands);
    ldr[i] = float4(mapped.x, mapped.y, mapped.z, hdr[i].w);
  }
}
