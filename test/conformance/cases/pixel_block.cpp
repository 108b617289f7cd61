#include "pixel_block.h"

static uint32_t PackColor(float4 c)
{
  const uint32_t r = uint32_t(LiteMath::clamp(c.x, 0.0f, 1.0f) * 255.0f);
  const uint32_t g = uint32_t(LiteMath::clamp(c.y, 0.0f, 1.0f) * 255.0f);
  const uint32_t b = uint32_t(LiteMath::clamp(c.z, 0.0f, 1.0f) * 255.0f);
  return r | (g << 8) | (b << 16);
}

bool PixelBlock::kernel_InitRay(float4* rayDir, uint32_t tidX, uint32_t tidY)
{
  const float u = (float(tidX) + 0.5f) / float(m_width) * 2.0f - 1.0f;
  const float v = (float(tidY) + 0.5f) / float(m_width) * 2.0f - 1.0f;
  *rayDir = LiteMath::normalize(float4(u, v, 1.0f, 0.0f));
  return u * u + v * v < 0.8f;  // the lens's disc
}

void PixelBlock::kernel_Shade(const float4* rayDir, uint32_t* out_color, uint32_t tidX, uint32_t tidY, uint32_t alpha)
{
  const float4 d = *rayDir;
  out_color[tidY * m_width + tidX] = PackColor(float4(0.5f + 0.5f * d.x, 0.5f + 0.5f * d.y, d.z * d.z, 1.0f)) | (alpha << 24);
}

void PixelBlock::MainFunc(uint32_t tidX, uint32_t tidY, uint32_t* out_color)
{
  const uint32_t opaque = 0xFF;  // the same for every thread
  float4 rayDir;
  if (!kernel_InitRay(&rayDir, tidX, tidY))
    return;  // outside the lens: the pixel keeps what it had
  kernel_Shade(&rayDir, out_color, tidX, tidY, opaque);
}

void PixelBlock::MainFuncBlock(uint32_t tidX, uint32_t tidY, uint32_t* out_color, uint32_t a_numPasses)
{
  for (uint32_t y = 0; y < tidY; y++)
    for (uint32_t x = 0; x < tidX; x++)
      for (uint32_t p = 0; p < a_numPasses; p++)
        MainFunc(x, y, out_color);
}
