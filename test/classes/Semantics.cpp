#include "Semantics.h"

#include <cmath>

namespace
{
constexpr int kRounds = 2;
}

void Semantics::Evaluate(int n, float* out)
{
  kernel1D_Evaluate(n, out);
}

void Semantics::kernel1D_Evaluate(int n, float* out)
{
  for (int i = 0; i < n; i++)
  {
    const float x = float(i) - 10.0f;
    float4x4 identity;                      // LiteMath: the identity
    const float4x4 m(1, 2, 3, 4,            // rows, as written on paper
                     5, 6, 7, 8,
                     9, 10, 11, 12,
                     0, 0, 0, 1);
    const float4 v = m * (identity * float4(x, 1.0f, 2.0f, 1.0f));
    const int3 a(i + 7, 9, -4), b(2, 4, 3);
    const float3 ratio = to_float3(a) / to_float3(b);   // float division, not integer
    Interval range;                                     // default member initialisers
    float w[4] = {1.5f};                                // the rest are zero
    int sum = 0;
    for (int j = 0, k = 3; j < 4; ++j, --k)              // two loop variables
      sum += j * k;
    {                                                   // names that shadow others (valid C++)
      const int n = kRounds;                            // the parameter n
      for (int i = 0; i < n; ++i)                       // the loop's i
      {
        const int kRounds = 10;                         // a namespace constant
        sum += i * kRounds;
      }
    }
    out[i * 8 + 0] = v.x + v.y * 0.5;                   // promoted to double in C++
    out[i * 8 + 1] = float((i - 7) % 5);                // negative remainders keep C++'s sign
    out[i * 8 + 2] = std::round(x * 0.5f);              // halves away from zero
    out[i * 8 + 3] = ratio.x + ratio.z;
    out[i * 8 + 4] = range.lo + range.hi + w[0] + w[3];
    out[i * 8 + 5] = float(sum) + float(3000000000u) * 1e-9f;
    out[i * 8 + 6] = m_a.z + m_b.x;                     // struct members' std430 offsets
    out[i * 8 + 7] = v.w;
  }
}

void Semantics::Steps(int n, int steps, float* out)
{
  for (int s = 0; s < steps; ++s)  // a host loop around kernels
  {
    kernel1D_Accumulate(n, out);
    m_time += 1.0f;                // seen by the kernels recorded after it, not before
    if (s % 2 == 0)
      m_time++;
    for (int i = 0; i < n; i++)    // an RTV loop inside the host loop
      kernel_Bump(i, out);
  }
}

void Semantics::kernel1D_Accumulate(int n, float* out)
{
  for (int i = 0; i < n; i++)
    out[i] += m_time * float(i + 1);
}

void Semantics::kernel_Bump(int tid, float* out)
{
  out[tid] += 0.25f * m_time;
}

void Semantics::Transform(int n, const float4* in, float* out)
{
  kernel1D_Transform(n, in, out);
}

// Locals set up by statements before the loop nest, not only by their declarations: the loop sees
// them as those statements left them, and so do the statements after it. A statement that sets a
// member runs once.
void Semantics::kernel1D_Transform(int n, const float4* in, float* out)
{
  float4x4 m = m_xf;
  m(0, 3) = 0.5f;                     // an element, through operator()
  m.set_col(1, float4(0.0f, 2.0f, 0.0f, 0.0f));
  float bias = 1.0f;
  if (m_time > 0.0f)
    bias *= m_time;
  m(1, 0) += 0.25f;
  m(1, 1) += 0.25f;
  m_transforms += 1;
  for (int i = 0; i < n; i++)
  {
    const float4 p = m * in[i];
    out[i] = p.x + 0.5f * p.y + bias;
  }
  m_corner = m(0, 3) + m(1, 0) + bias;
}
