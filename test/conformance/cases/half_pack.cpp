#include "half_pack.h"

void HalfPack::Pack(int n, const float4* a_in) { kernel1D_Pack(n, a_in); }
void HalfPack::Unpack(int n, float4* a_out) { kernel1D_Unpack(n, a_out); }

void HalfPack::kernel1D_Pack(int n, const float4* a_in)
{
  for (int i = 0; i < n; i++)
    m_packed[i] = half4(a_in[i] * 0.5f);
}

void HalfPack::kernel1D_Unpack(int n, float4* a_out)
{
  for (int i = 0; i < n; i++)
    a_out[i] = to_float4(m_packed[i]) * 2.0f;
}
