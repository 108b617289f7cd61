// A kernel that returns bool in a thread loop: `if (!kernel_Bounce(...)) break;` ends that thread's
// loop (kernel_slicer's loop-break form).
#pragma once
#include "LiteMath.h"
#include <cstdint>
using namespace LiteMath;

class BounceLoop
{
public:
  virtual void Trace(uint32_t n, const float* a_energy [[size("n")]], float4* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}
  int m_maxBounces = 8;

protected:
  void kernel_Init(uint32_t tid, const float* a_energy, float4* a_state);
  bool kernel_Bounce(uint32_t tid, float4* a_state);
  void kernel_Write(uint32_t tid, const float4* a_state, float4* a_out);
};
