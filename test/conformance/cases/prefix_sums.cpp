#include "prefix_sums.h"

#include <functional>
#include <numeric>

void PrefixSums::Scan(const int* a_data, unsigned a_size, int* a_outExc, int* a_outInc)
{
  std::exclusive_scan(a_data, a_data + a_size, a_outExc, 0);
  std::inclusive_scan(a_data, a_data + a_size, a_outInc, std::plus<int>(), 7);
  kernel1D_Square(a_outInc, a_size);
}

void PrefixSums::kernel1D_Square(int* a_data, unsigned a_size)
{
  for (unsigned i = 0; i < a_size; i++)
    a_data[i] = a_data[i] % 1000;
}
