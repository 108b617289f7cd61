#include "transforms.h"

Transforms::Transforms()
{
  m_rows = make_float4x4_from_rows(float4(1, 2, 0, 0.5f), float4(0, 1, 3, -1), float4(2, 0, 1, 0.25f), float4(0, 0, 0, 1));
  m_cols = make_float4x4_from_cols(float4(0.5f, 0, 0, 0), float4(0, 2, 0, 0), float4(0, 0, 1.5f, 0), float4(1, -2, 3, 1));
}

void Transforms::Apply(int n, const float4* a_in, float4* a_out) { kernel1D_Apply(n, a_in, a_out); }

void Transforms::kernel1D_Apply(int n, const float4* a_in, float4* a_out)
{
  for (int i = 0; i < n; i++)
  {
    const float4 p = mul4x4x4(m_cols, mul4x4x4(m_rows, a_in[i]));
    const float3x3 r = rotate3x3X(m_angle) * rotate3x3Y(2.0f * m_angle) * rotate3x3Z(-m_angle);
    const float3 q = r * to_float3(p);
    // Columns changed through a running index, as code filling a matrix does (ISPC finds m[k++] once).
    float4x4 basis;
    int k = 0;
    basis[k++] += p;
    basis[k++] -= float4(0.5f, 0.25f, 0.0f, 0.0f);
    basis[k] *= 2.0f;
    a_out[i] = to_float4(q, p.w) + 0.125f * (basis * a_in[i]);
  }
}
