#include "tonemap.h"

#include <algorithm>

static inline float ReinhardExtended(float v, float maxWhite)
{
  const float numerator = v * (1.0f + (v / (maxWhite * maxWhite)));
  return numerator / (1.0f + v);
}

float Gamma(float v) { return std::pow(std::max(v, 0.0f), 1.0f / 2.2f); }

namespace
{
constexpr float kExposure = 1.5f;
}

float Tonemap::Luminance(float4 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

void Tonemap::Apply(int w, int h, const float4* a_hdr, float4* a_ldr) { kernel2D_Apply(w, h, a_hdr, a_ldr); }

void Tonemap::kernel2D_Apply(int w, int h, const float4* a_hdr, float4* a_ldr)
{
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
    {
      const float4 c = a_hdr[y * w + x] * kExposure;
      const float l = Luminance(c);
      const float scale = l > 0.0f ? ReinhardExtended(l, m_white) / l : 0.0f;
      const float4 t = c * scale;
      a_ldr[y * w + x] = float4(Gamma(t.x), Gamma(t.y), Gamma(t.z), 1.0f);
    }
}
