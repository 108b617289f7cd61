#include "array_sum.h"

void ArraySum::CalcArraySum(const int* a_data, unsigned int a_dataSize) { kernel1D_ArraySum(a_data, a_dataSize); }

void ArraySum::kernel1D_ArraySum(const int* a_data, size_t a_dataSize)
{
  m_sum = 0;
  for (size_t i = 0; i < a_dataSize; i++)
    m_sum += a_data[i] * int(i % 3);
}
