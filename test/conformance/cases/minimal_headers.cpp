#include "minimal_headers.h"

void Decay::Run(int n, float* a_values) { kernel1D_Run(n, a_values); }

void Decay::kernel1D_Run(int n, float* a_values)
{
  for (int i = 0; i < n; i++)
  {
    const float r = m_rates[i % int(m_rates.size())];
    a_values[i] = a_values[i] * r > m_floor ? a_values[i] * r : m_floor;
  }
}
