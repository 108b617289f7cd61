// A random generator's state passed by pointer to helpers that advance it (gen->state).
#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <vector>
using namespace LiteMath;

struct RandomGen
{
  uint2 state;
};

static inline unsigned int NextState(RandomGen* gen)
{
  const unsigned int x = (gen->state).x * 17 + (gen->state).y * 13123;
  (gen->state).x = (x << 13) ^ x;
  (gen->state).y ^= (x << 7);
  return x;
}

static inline float rndFloat1(RandomGen* gen)
{
  const unsigned int x = NextState(gen);
  return float(x & 0x00FFFFFFu) * (1.0f / 16777216.0f);
}

class NoisyFill
{
public:
  explicit NoisyFill(uint32_t a_count);
  virtual void Fill(uint32_t n, float* a_out [[size("n")]], uint32_t a_rounds);
  virtual void CommitDeviceData() {}
  std::vector<RandomGen> m_gens;

protected:
  void kernel1D_Fill(uint32_t n, float* a_out, uint32_t a_rounds);
};
