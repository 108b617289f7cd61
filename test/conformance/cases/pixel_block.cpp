#include "pixel_block.h"

static uint32_t PackColor(float4 c)
{
  const uint32_t r = uint32_t(LiteMath::clamp(c.x, 0.0f, 1.0f) * 255.0f);
  const uint32_t g = uint32_t(LiteMath::clamp(c.y, 0.0f, 1.0f) * 255.0f);
  const uint32_t b = uint32_t(LiteMath::clamp(c.z, 0.0f, 1.0f) * 255.0f);
  return r | (g << 8) | (b << 16);
}

// A helper that takes its arrays as arrays (kernel_slicer's RayBoxIntersectionLite(..., const float boxMin[3], ...)).
struct Tint
{
  float rgb[3];
};

static float Exposure() { return 0.9f; }  // a helper of the .cpp the per-thread function calls

static float Weighted3(const float values[3], const float weights[3])
{
  return values[0] * weights[0] + values[1] * weights[1] + values[2] * weights[2];
}

bool PixelBlock::kernel_InitRay(float4* rayDir, uint32_t tidX, uint32_t tidY)
{
  const float u = (float(tidX) + 0.5f) / float(m_width) * 2.0f - 1.0f;
  const float v = (float(tidY) + 0.5f) / float(m_width) * 2.0f - 1.0f;
  *rayDir = LiteMath::normalize(float4(u, v, 1.0f, 0.0f));
  return u * u + v * v < 0.8f;  // the lens's disc
}

void PixelBlock::kernel_Bounce(float4* rayDir, uint32_t* done, uint32_t tidX, uint32_t tidY)
{
  const float4 d = *rayDir;
  *rayDir = LiteMath::normalize(float4(0.8f * d.x + 0.2f + 0.001f * float(tidY), d.y, d.z, 0.0f));
  *done = rayDir->x > 0.3f + 0.002f * float(tidX) ? 1u : 0u;
}

void PixelBlock::kernel_Shade(const float4* rayDir, const float* exposure, uint32_t* out_color, uint32_t tidX, uint32_t tidY, uint32_t alpha)
{
  const float4 d = *rayDir * *exposure;
  Tint tint;
  tint.rgb[0] = d.x;
  tint.rgb[1] = 0.5f;
  tint.rgb[2] = d.z;
  const float weights[3] = {0.2f, 0.3f, 0.5f};
  const float blue = Weighted3(tint.rgb, weights);  // a local struct's array field, and a local array
  out_color[tidY * m_width + tidX] = PackColor(float4(0.5f + 0.5f * d.x, 0.5f + 0.5f * d.y, blue, 1.0f)) | (alpha << 24);
}

void PixelBlock::MainFunc(uint32_t tidX, uint32_t tidY, uint32_t* out_color)
{
  const uint32_t opaque = 0xFF;  // the same for every thread
  float4 rayDir;
  if (!kernel_InitRay(&rayDir, tidX, tidY))
    return;  // outside the lens: the pixel keeps what it had
  uint32_t done;
  for (uint32_t bounce = 0; bounce < 4; bounce++)
  {
    kernel_Bounce(&rayDir, &done, tidX, tidY);
    if (done != 0u)
      break;  // a test of the thread's own local
  }
  float exposure = Exposure();  // starts at a call's result: the megakernel computes it per thread
  kernel_Shade(&rayDir, &exposure, out_color, tidX, tidY, opaque);
}

void PixelBlock::MainFuncBlock(uint32_t tidX, uint32_t tidY, uint32_t* out_color, uint32_t a_numPasses)
{
  for (uint32_t y = 0; y < tidY; y++)
    for (uint32_t x = 0; x < tidX; x++)
      for (uint32_t p = 0; p < a_numPasses; p++)
        MainFunc(x, y, out_color);
}
