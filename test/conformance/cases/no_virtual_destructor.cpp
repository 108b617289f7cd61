#include "no_virtual_destructor.h"

void Brighten::Apply(int n, float4* a_pixels) { kernel1D_Apply(n, a_pixels); }

void Brighten::kernel1D_Apply(int n, float4* a_pixels)
{
  for (int i = 0; i < n; ++i)
    a_pixels[i] = a_pixels[i] * m_tint[i % m_tint.size()];
}
