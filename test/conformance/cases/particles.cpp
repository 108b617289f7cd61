#include "particles.h"

void ParticleStep::Advance(Particle* p, float dt)
{
  p->vel.y -= 9.81f * dt;
  p->pos += p->vel * dt;
  if (p->pos.y < 0.0f)
  {
    p->pos.y = -p->pos.y;
    p->vel.y = -0.8f * p->vel.y;
  }
}

void ParticleStep::Step(float dt, int steps)
{
  for (int s = 0; s < steps; s++)
    kernel1D_Step(int(m_particles.size()), dt);
}

void ParticleStep::kernel1D_Step(int count, float dt)
{
  for (int i = 0; i < count; i++)
    Advance(&m_particles[i], dt);
}
