#include "random_gen.h"

NoisyFill::NoisyFill(uint32_t a_count) : m_gens(a_count)
{
  for (uint32_t i = 0; i < a_count; i++)
    m_gens[i].state = uint2(i * 7919u + 1u, i * 104729u + 3u);
}

void NoisyFill::Fill(uint32_t n, float* a_out, uint32_t a_rounds) { kernel1D_Fill(n, a_out, a_rounds); }

void NoisyFill::kernel1D_Fill(uint32_t n, float* a_out, uint32_t a_rounds)
{
  for (uint32_t i = 0; i < n; i++)
  {
    RandomGen gen = m_gens[i];
    float sum = 0.0f;
    for (uint32_t r = 0; r < a_rounds; r++)
      sum += rndFloat1(&gen);
    a_out[i] = sum;
    m_gens[i] = gen;
  }
}
