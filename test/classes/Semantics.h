// C++ semantics the GPU code must keep (found in review): matrices, double promotions, signed
// remainders, rounding, default member initialisers, array fillers, member updates between
// kernels, RTV loops inside host loops, struct members' std430 alignment, locals set by statements
// before a loop nest, locals that shadow a parameter, a loop variable or a namespace constant.
#pragma once
#include "LiteMath.h"

#include <vector>

using namespace LiteMath;

struct Light  // 12 bytes, std430 alignment 4: two in a row sit at 0 and 12
{
  float x, y, z;
};

struct Interval
{
  float lo = 0.25f;
  float hi = 8.0f;
};

class Semantics
{
public:
  virtual ~Semantics() = default;
  virtual void Evaluate(int n, [[crossrt::size("n * 8")]] float* out);
  virtual void Steps(int n, int steps, [[crossrt::size("n")]] float* out);
  virtual void Transform(int n, [[crossrt::size("n")]] const float4* in, [[crossrt::size("n")]] float* out);
  virtual void CommitDeviceData() {}

  Light m_a{1.0f, 2.0f, 3.0f}, m_b{4.0f, 5.0f, 6.0f};
  float m_time = 0.0f;
  float4x4 m_xf;              // Transform's matrix, which it adjusts in a local copy
  float m_corner = 0.0f;      // set after Transform's loop from the adjusted copy
  int m_transforms = 0;       // counted before Transform's loop, once a call

protected:
  void kernel1D_Evaluate(int n, float* out);
  void kernel1D_Accumulate(int n, float* out);
  void kernel_Bump(int tid, float* out);
  void kernel1D_Transform(int n, const float4* in, float* out);
};
