#include "accum_grid.h"

void AccumGrid::Accumulate(uint32_t n, const float* a_values)
{
  ReduceAddInit(m_accum, m_accum.size());
  kernel1D_Accumulate(n, a_values);
  ReduceAddComplete(m_accum);
}

void AccumGrid::kernel1D_Accumulate(uint32_t n, const float* a_values)
{
  for (uint32_t i = 0; i < n; i++)
  {
    ReduceAdd<float, uint32_t>(m_accum, i % 8u, a_values[i]);
    ReduceAdd<float, uint32_t>(m_accum, 0u, 1.0f);
  }
}
