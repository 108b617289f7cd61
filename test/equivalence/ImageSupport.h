// Helpers of the image and texture equivalence tests.
#pragma once
#include "Image2D.h"
#include "TestSupport.h"

#include <algorithm>
#include <cmath>

// w x h texels of random channels in [0, 1), the same for a given seed.
inline LiteImage::Image2D<LiteMath::float4> RandomImage(uint32_t w, uint32_t h, unsigned seed)
{
  const auto v = RandomFloats(int(4 * w * h), seed, 0.0f, 1.0f);
  LiteImage::Image2D<LiteMath::float4> img(w, h);
  for (uint32_t i = 0; i < w * h; ++i) img.data()[i] = LiteMath::float4(v[4 * i], v[4 * i + 1], v[4 * i + 2], v[4 * i + 3]);
  return img;
}

// The largest difference of two texels over their channels; NaN where a channel's is (std::max
// would drop it, and `MaxDifference(...) <= tolerance` would pass).
inline float MaxDifference(const LiteMath::float4& a, const LiteMath::float4& b)
{
  float worst = 0.0f;
  for (int c = 0; c < 4; ++c)
    if (const float d = std::fabs(a[c] - b[c]); std::isnan(d) || d > worst) worst = d;
  return worst;
}
