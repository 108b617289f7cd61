// A helper that updates an element of a member vector through a pointer to it: p->pos += p->vel * dt.
#pragma once
#include "LiteMath.h"
#include <vector>
using namespace LiteMath;

struct Particle
{
  float4 pos;
  float4 vel;
};

class ParticleStep
{
public:
  ParticleStep() {}
  virtual void Step(float dt, int steps);
  virtual void CommitDeviceData() {}
  std::vector<Particle> m_particles;

protected:
  void kernel1D_Step(int count, float dt);
  static void Advance(Particle* p, float dt);
};
