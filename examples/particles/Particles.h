// A plain C++ class: a particle system step plus statistics computed with member reductions.
// Nothing here knows about GPUs; CrossRT derives Particles_Vulkan and Particles_CPU from it.
#pragma once
#include "LiteMath.h"

#include <vector>

using LiteMath::float4;

class Particles
{
public:
  Particles() = default;
  virtual ~Particles() = default;

  // Advances n particles by dt under gravity with a bouncy floor, then measures them.
  virtual void Step(int n, float dt,
                    [[crossrt::size("n")]] float4* positions,
                    [[crossrt::size("n")]] float4* velocities);

  virtual void CommitDeviceData() {}
  virtual void GetExecutionTime(const char* a_funcName, float a_out[4]);

  // Results of the last Step (reductions over all particles).
  float4 m_boxMin, m_boxMax;  // bounding box of the positions
  float4 m_momentum;          // sum of the velocities
  float m_kineticEnergy = 0.0f;
  int m_bounces = 0;          // particles that hit the floor during the step

protected:
  void kernel1D_Advance(int n, float dt, float4* positions, float4* velocities);
  void kernel1D_Measure(int n, const float4* positions, const float4* velocities);

  float m_gravity = -9.81f;
  float m_restitution = 0.8f;
  float m_timeMs = 0.0f;
};
