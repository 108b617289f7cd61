#include "Walkers.h"

#include <cmath>

using namespace LiteMath;

void Walkers::Walk(int n, int steps, const float4* starts, float4* ends, int* bounces)
{
  const float dt = 1.0f / float(steps > 0 ? steps : 1);  // read by the thread loop: a by-value argument on the GPU
  for (int i = 0; i < n; i++)
  {
    WalkerState state;
    float travelled;
    kernel_Start(i, starts, &state, &travelled);
    for (int step = 0; step < steps; step++)
      kernel_Step(i, dt, &state, &travelled);
    kernel_Finish(i, &state, &travelled, ends, bounces);
  }
}

void Walkers::kernel_Start(uint32_t tid, const float4* starts, WalkerState* state, float* travelled)
{
  const float4 p = starts[tid];
  state->position = float4(p.x, p.y, p.z, 0.0f);
  // A velocity from the start itself, so that walkers differ.
  state->velocity = float4(3.0f * p.y + 0.5f, -2.0f * p.z + 0.25f, 1.5f * p.x - 0.75f, 0.0f);
  state->bounces = 0;
  *travelled = 0.0f;  // it starts at zero already: assigned anyway, as a reader would expect
}

void Walkers::kernel_Step(uint32_t tid, float dt, WalkerState* state, float* travelled)
{
  (void)tid;
  float4 p = state->position + state->velocity * dt;
  if (std::fabs(p.x) > m_box) { state->velocity.x = -state->velocity.x; p.x = p.x > 0.0f ? 2.0f * m_box - p.x : -2.0f * m_box - p.x; state->bounces++; }
  if (std::fabs(p.y) > m_box) { state->velocity.y = -state->velocity.y; p.y = p.y > 0.0f ? 2.0f * m_box - p.y : -2.0f * m_box - p.y; state->bounces++; }
  if (std::fabs(p.z) > m_box) { state->velocity.z = -state->velocity.z; p.z = p.z > 0.0f ? 2.0f * m_box - p.z : -2.0f * m_box - p.z; state->bounces++; }
  *travelled += length(p - state->position);
  state->position = p;
}

void Walkers::kernel_Finish(uint32_t tid, const WalkerState* state, const float* travelled, float4* ends, int* bounces)
{
  ends[tid] = float4(state->position.x, state->position.y, state->position.z, *travelled);
  bounces[tid] = state->bounces;
}
