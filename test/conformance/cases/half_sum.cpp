#include "half_sum.h"

void HalfSum::Sum(const int* a_data, unsigned int a_dataSize) { kernel1D_Sum(a_data, int(a_dataSize)); }

void HalfSum::kernel1D_Sum(const int* a_data, int a_dataSize)
{
  m_summ = 0;
  for (int i = a_dataSize / 2; i <= a_dataSize - 1; i++)
  {
    int number = a_data[i];
    if (number > 0)
      m_summ += number;
  }
}
