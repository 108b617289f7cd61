#include "min_max_pair.h"

static void SplitMinMax(float a, float b, float* lo, float* hi)
{
  *lo = a < b ? a : b;
  hi[0] = a < b ? b : a;
}

void MinMaxPair::Run(int n, const float* a_a, const float* a_b, float* a_lo, float* a_hi) { kernel1D_Run(n, a_a, a_b, a_lo, a_hi); }

void MinMaxPair::kernel1D_Run(int n, const float* a_a, const float* a_b, float* a_lo, float* a_hi)
{
  for (int i = 0; i < n; i++)
  {
    float lo, hi;
    SplitMinMax(a_a[i], a_b[i], &lo, &hi);
    a_lo[i] = lo;
    a_hi[i] = hi;
  }
}
