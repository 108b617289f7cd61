#include "gather.h"

static inline float read_data(const float* a_data, uint32_t a_id) { return a_data[a_id]; }

Gather::Gather() : m_table(64), m_indices(64)
{
  for (uint32_t i = 0; i < 64; i++)
  {
    m_table[i] = float(i * i) * 0.25f;
    m_indices[i] = (i * 37u) % 64u;
  }
}

float Gather::Lookup(uint32_t a_id) const { return read_data(m_table.data() + 2, a_id % 60u); }

void Gather::Run(uint32_t n, float* a_out) { kernel1D_Run(n, a_out); }

void Gather::kernel1D_Run(uint32_t n, float* a_out)
{
  for (uint32_t i = 0; i < n; i++)
  {
    const uint32_t* idx = m_indices.data();
    a_out[i] = Lookup(idx[i % 64u]) + m_table.data()[i % 64u];
  }
}
