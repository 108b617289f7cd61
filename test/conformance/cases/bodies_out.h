// kernel_slicer's n-body form: the control function's output pointer has no size, because only host
// code uses it. The kernels step the member vector; then memcpy copies it out, as the original does.
#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <vector>
using namespace LiteMath;

struct BodyState
{
  float4 posAndMass;
  float4 velocity;
};

class BodiesOut
{
public:
  BodiesOut() : m_bodies(64) {}
  void SetSteps(uint32_t steps) { m_steps = steps; }
  virtual void Perform(BodyState* out_bodies);
  virtual void CommitDeviceData() {}

  void kernel1D_Seed(uint32_t count);
  void kernel1D_Step(uint32_t count, float dt);
  std::vector<BodyState> m_bodies;
  uint32_t m_steps = 3;
};
