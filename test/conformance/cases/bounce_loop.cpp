#include "bounce_loop.h"

void BounceLoop::Trace(uint32_t n, const float* a_energy, float4* a_out)
{
  for (uint32_t i = 0; i < n; i++)
  {
    float4 state;
    kernel_Init(i, a_energy, &state);
    for (int b = 0; b < m_maxBounces; b++)
    {
      if (!kernel_Bounce(i, &state))
        break;
    }
    kernel_Write(i, &state, a_out);
  }
}

void BounceLoop::kernel_Init(uint32_t tid, const float* a_energy, float4* a_state)
{
  *a_state = float4(a_energy[tid], 0.0f, 0.0f, 0.0f);
}

bool BounceLoop::kernel_Bounce(uint32_t tid, float4* a_state)
{
  float4 s = *a_state;
  s.x *= 0.5f;
  s.y += 1.0f;
  *a_state = s;
  return s.x > 0.1f;
}

void BounceLoop::kernel_Write(uint32_t tid, const float4* a_state, float4* a_out) { a_out[tid] = *a_state; }
