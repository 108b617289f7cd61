// A per-pixel generator as users write one: a struct whose non-const method advances its own state
// (a local of the thread, not the class), a static hash helper, a static constexpr member as an
// array size, {} zero-initialisation, a struct-returning helper in a conditional, a structured
// binding, std::fmod, std::isnan and std::isfinite, and an early continue. Both helpers are marked
// noinline, in the two spellings (a call on ISPC too).
#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <limits>
#include <vector>

using LiteMath::float2;
using LiteMath::float3;

struct Rng
{
  uint32_t state;
  float Next()
  {
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    return float(state & 0xFFFFFFu) / float(0x1000000);
  }
};

struct Pair
{
  float a;
  int b;
};

class HashNoise
{
public:
  HashNoise() = default;
  virtual ~HashNoise() = default;
  virtual void Run(int w, int h, float* out [[crossrt::size("w * h")]]);
  virtual void CommitDeviceData() {}
  static constexpr int kTaps = 5;

protected:
  void kernel2D_Run(int w, int h, float* out);
  float Weight(int k) const { return 1.0f / float(k + 1); }
};
