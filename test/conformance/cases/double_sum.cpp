#include "double_sum.h"

void DoubleSum::Sum(const double* a_data, size_t a_dataSize) { kernel1D_Sum(a_data, a_dataSize); }

void DoubleSum::kernel1D_Sum(const double* a_data, size_t a_dataSize)
{
  m_summ = 0.0;
  for (size_t i = 0; i < a_dataSize; i++)
  {
    const double number = a_data[i] * 2.0 + 0.1;  // 0.1 in double: 0.1f is 1.5e-9 off
    if (number > 0.0)
      m_summ += number;
  }
}
