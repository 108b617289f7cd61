#include "Particles.h"

#include <chrono>

using namespace LiteMath;

void Particles::Step(int n, float dt, float4* positions, float4* velocities)
{
  const auto start = std::chrono::steady_clock::now();
  m_boxMin = float4(INF_POSITIVE);
  m_boxMax = float4(INF_NEGATIVE);
  m_momentum = float4(0.0f);
  m_kineticEnergy = 0.0f;
  m_bounces = 0;
  kernel1D_Advance(n, dt, positions, velocities);
  kernel1D_Measure(n, positions, velocities);
  m_timeMs = std::chrono::duration<float, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void Particles::kernel1D_Advance(int n, float dt, float4* positions, float4* velocities)
{
  for (int i = 0; i < n; i++)
  {
    float4 v = velocities[i];
    float4 p = positions[i] + v * dt;
    v.y += m_gravity * dt;
    if (p.y < 0.0f)  // bounce on the floor y = 0
    {
      p.y = -p.y * m_restitution;
      v.y = -v.y * m_restitution;
      m_bounces += 1;
    }
    positions[i] = p;
    velocities[i] = v;
  }
}

void Particles::kernel1D_Measure(int n, const float4* positions, const float4* velocities)
{
  for (int i = 0; i < n; i++)
  {
    const float4 p = positions[i];
    const float4 v = velocities[i];
    m_boxMin = min(m_boxMin, p);
    m_boxMax = max(m_boxMax, p);
    m_momentum += v;
    m_kineticEnergy += 0.5f * dot(v, v);
  }
}

void Particles::GetExecutionTime(const char* a_funcName, float a_out[4])
{
  (void)a_funcName;
  a_out[0] = a_out[1] = a_out[2] = 0.0f;
  a_out[3] = m_timeMs;
}
