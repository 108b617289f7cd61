#include "int_division.h"

void IntDivision::Divide(int n, const int* a, const int* b, const uint32_t* u, int4* quotients, uint4* unsignedQuotients)
{
  kernel1D_Divide(n, a, b, u, quotients, unsignedQuotients);
}

void IntDivision::kernel1D_Divide(int n, const int* a, const int* b, const uint32_t* u, int4* quotients, uint4* unsignedQuotients)
{
  for (int i = 0; i < n; i++)
  {
    const int x = a[i];
    const int y = b[i] == 0 ? 1 : b[i];
    const uint32_t v = u[i];
    const uint32_t w = uint32_t(y < 0 ? -y : y);
    const uint32_t step = uint32_t(m_step < 0 ? -m_step : m_step);
    quotients[i] = int4(x / y, x % y, x / m_step + x % m_step, x % 10 + i / (1 + i % 5));
    unsignedQuotients[i] = uint4(v / w, v % w, v / step + v % step, v % 1000u + uint32_t(i) / w);
  }
}
