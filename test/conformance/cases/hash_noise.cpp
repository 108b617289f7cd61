#include "hash_noise.h"
#include <algorithm>
#include <cmath>

__attribute__((noinline)) static uint32_t PcgHash(uint32_t v)
{
  const uint32_t state = v * 747796405u + 2891336453u;
  const uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

[[gnu::noinline]] static Pair MakePair(float a, int b) { return Pair{a, b}; }  // called under a condition that differs per lane

void HashNoise::Run(int w, int h, float* out) { kernel2D_Run(w, h, out); }

void HashNoise::kernel2D_Run(int w, int h, float* out)
{
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      Rng rng{PcgHash(uint32_t(y * w + x))};
      float taps[kTaps] = {};
      for (int k = 0; k < kTaps; ++k)
        taps[k] = rng.Next() * Weight(k);
      auto total = 0.0f;
      for (int k = 0; k < kTaps; ++k) total += taps[k];
      const Pair p = total > 1.0f ? MakePair(total, 1) : MakePair(-total, 2);
      const auto [value, tag] = p;
      float r = std::fmod(value, 0.7f) + std::floor(total) * 0.1f;
      if (std::isnan(r) || !std::isfinite(r)) r = 0.0f;
      r += float(std::abs(tag - 3)) * 0.01f;
      if (x == 0 && y == 0)
      {
        out[0] = std::numeric_limits<float>::max();
        continue;
      }
      out[y * w + x] = r;
    }
}
