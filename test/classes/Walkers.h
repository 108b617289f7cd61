// A 1D thread loop with a struct of per-thread state: each walker starts from its point, takes
// `steps` steps inside a box (bouncing off its walls), and reports where it ended. Translated with
// EXECUTION_MODE megakernel, so the Vulkan class starts in that mode.
#pragma once
#include "LiteMath.h"

#include <cstdint>

using LiteMath::float4;

struct WalkerState
{
  float4 position;
  float4 velocity;
  int bounces;  // walls hit so far
};

class Walkers
{
public:
  virtual ~Walkers() = default;
  virtual void Walk(int n, int steps, [[crossrt::size("n")]] const float4* starts, [[crossrt::size("n")]] float4* ends,
                    [[crossrt::size("n")]] int* bounces);
  virtual void CommitDeviceData() {}
  virtual void GetExecutionTime(const char*, float a_out[4]) { a_out[0] = a_out[1] = a_out[2] = a_out[3] = 0.0f; }

  float m_box = 1.0f;  // walls at -m_box and +m_box on every axis

protected:
  void kernel_Start(uint32_t tid, const float4* starts, WalkerState* state, float* travelled);
  void kernel_Step(uint32_t tid, float dt, WalkerState* state, float* travelled);
  void kernel_Finish(uint32_t tid, const WalkerState* state, const float* travelled, float4* ends, int* bounces);
};
