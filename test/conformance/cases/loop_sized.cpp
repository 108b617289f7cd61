#include "loop_sized.h"

void LoopSized::Sum(const int* a_data, unsigned int a_last) { kernel1D_Sum(a_data, a_last); }

void LoopSized::Scale(const float* a_in, float* a_out, uint32_t a_count) { kernel1D_Scale(a_in, a_out, a_count); }

void LoopSized::kernel1D_Sum(const int* a_data, unsigned int a_last)
{
  m_sum = 0;
  for (unsigned int i = 0; i <= a_last; i++)
  {
    const int number = a_data[i];
    if (number > 0)
      m_sum += number;
  }
}

void LoopSized::kernel1D_Scale(const float* a_in, float* a_out, uint32_t a_count)
{
  for (uint32_t i = 0; i < a_count; ++i)
    a_out[i] = a_in[i] * m_factor;
}
