#include "conversions.h"

void Conversions::Run(int n, const float4* a_in, float4* a_out, int4* a_ints) { kernel1D_Run(n, a_in, a_out, a_ints); }

void Conversions::kernel1D_Run(int n, const float4* a_in, float4* a_out, int4* a_ints)
{
  for (int i = 0; i < n; i++)
  {
    const float4 v = a_in[i];
    const float3 xyz = to_float3(v);
    const int2 cell = int2(float2(v.x, v.y) * 4.0f);
    const float4 c = cross3(v, float4(0.0f, 0.0f, 1.0f, 0.0f));
    const float wrapped = mod(v.z * 10.0f, 3.0f);
    const float angle = M_TWOPI * fract(v.w) * INV_PI;
    a_out[i] = float4(length(xyz) + c.x, wrapped, angle, c.y);
    a_ints[i] = to_int4(int3(cell.x, cell.y, i), -i);
  }
}
