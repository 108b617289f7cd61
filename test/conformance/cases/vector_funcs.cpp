#include "vector_funcs.h"

using namespace LiteMath;

void VectorFuncs::kernel1D_Apply(const float4* a_in, float4* a_out, int n)
{
  for (int i = 0; i < n; ++i)
  {
    const float4 v = a_in[i];
    const float3 p = to_float3(v);
    const float2 q = float2(v.y, v.w);
    const float4 a = abs(v) + float4(0.25f);  // positive, for sqrt, log and pow
    float4* out = a_out + 16 * i;
    out[0] = floor(v);
    out[1] = to_float4(ceil(p), fract(v.w));
    out[2] = float4(fract(q).x, fract(q).y, sign(q).x, sign(q).y);
    out[3] = sqrt(a);
    out[4] = to_float4(inversesqrt(to_float3(a)), 0.0f);
    out[5] = sin(v);
    out[6] = to_float4(cos(p), 1.0f);
    out[7] = exp(v * 0.25f);
    out[8] = log(a);
    out[9] = pow(a, float4(0.5f, 1.5f, 2.0f, 0.75f));
    out[10] = step(float4(0.0f, 0.5f, -0.5f, 1.0f), v);
    out[11] = to_float4(step(0.25f, p), 0.0f);
    out[12] = mod(v, float4(0.75f, 1.25f, 2.0f, 0.5f));
    out[13] = lerp(v, a, 0.3f);
    out[14] = mix(v, a, float4(0.0f, 0.25f, 0.5f, 1.0f));
    out[15] = to_float4(smoothstep(-0.5f, 0.5f, p), smoothstep(-1.0f, 1.0f, v.w));
  }
}

void VectorFuncs::Apply(const float4* a_in, float4* a_out, int n) { kernel1D_Apply(a_in, a_out, n); }
