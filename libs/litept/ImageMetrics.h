// How far a render is from a reference (libs/litept): the PSNR of the two as 8-bit sRGB images, as
// an image viewer shows them, and the mean relative squared error of the linear HDR radiance, which
// does not saturate. Used by path_tracer --compare and bench_path_tracer.
#pragma once
#include "LiteMath.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace litept {

// Linear radiance to an 8-bit sRGB value (clamped to [0, 1] first).
inline uint32_t Srgb8(float v)
{
  v = std::clamp(v, 0.0f, 1.0f);
  const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
  return uint32_t(std::lround(255.0f * s));
}

struct ImageError
{
  double psnr8 = 0.0;  // dB, of the 8-bit sRGB images (99 when they are equal)
  double relMse = 0.0;  // mean over pixels and channels of (a - b)^2 / (b^2 + 0.01), linear
};

// rgb of `image` against `reference` (same size; w is ignored).
inline ImageError CompareImages(const std::vector<LiteMath::float4>& image, const std::vector<LiteMath::float4>& reference)
{
  double se8 = 0.0, rel = 0.0;
  for (size_t i = 0; i < image.size(); ++i)
    for (int c = 0; c < 3; ++c)
    {
      const float a = image[i][c], b = reference[i][c];
      const double d8 = double(Srgb8(a)) - double(Srgb8(b));
      se8 += d8 * d8;
      rel += double(a - b) * double(a - b) / (double(b) * double(b) + 1e-2);
    }
  const double n = double(3 * std::max<size_t>(1, image.size()));
  ImageError e;
  e.psnr8 = se8 > 0.0 ? 10.0 * std::log10(255.0 * 255.0 / (se8 / n)) : 99.0;
  e.relMse = rel / n;
  return e;
}

}  // namespace litept
