#include "row_sums.h"

void RowSums::Sum(int w, int h, const float* a_in, float* a_sums) { kernel1D_Rows(w, h, a_in, a_sums); }

void RowSums::kernel1D_Rows(int w, int h, const float* a_in, float* a_sums)
{
  for (int y = 0; y < h; y++)
  {
    const float* row = a_in + y * w;
    float sum = 0.0f;
    for (int x = 0; x < w; x++)
      sum += row[x] * float(x + 1);
    a_sums[y] = sum + *row;
  }
}
