#include "bodies_out.h"
#include <cstring>

void BodiesOut::Perform(BodyState* out_bodies)
{
  kernel1D_Seed(uint32_t(m_bodies.size()));
  for (uint32_t i = 0; i < m_steps; ++i)
    kernel1D_Step(uint32_t(m_bodies.size()), 0.01f);
  memcpy(out_bodies, m_bodies.data(), m_bodies.size() * sizeof(BodyState));
}

void BodiesOut::kernel1D_Seed(uint32_t count)
{
  for (uint32_t i = 0; i < count; ++i)
  {
    const float a = 0.37f * float(i);
    m_bodies[i].posAndMass = float4(std::cos(a), std::sin(a), 0.1f * float(i % 7), 1.0f + 0.01f * float(i));
    m_bodies[i].velocity = float4(0.0f, 0.0f, 0.0f, 0.0f);
  }
}

void BodiesOut::kernel1D_Step(uint32_t count, float dt)
{
  for (uint32_t i = 0; i < count; ++i)
  {
    const float3 p = to_float3(m_bodies[i].posAndMass);
    const float3 toCenter = -p / (dot(p, p) + 0.1f);
    m_bodies[i].velocity = m_bodies[i].velocity + float4(toCenter.x, toCenter.y, toCenter.z, 0.0f) * dt;
    m_bodies[i].posAndMass = m_bodies[i].posAndMass + float4(m_bodies[i].velocity.x, m_bodies[i].velocity.y, m_bodies[i].velocity.z, 0.0f) * dt;
  }
}
