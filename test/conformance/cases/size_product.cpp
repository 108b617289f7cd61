#include "size_product.h"

void ImageScale::Scale(int w, int h, const float* a_in, float* a_out)
{
  kernel2D_Scale(w, h, a_in, a_out);
}

void ImageScale::kernel2D_Scale(int w, int h, const float* a_in, float* a_out)
{
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      a_out[y * w + x] = a_in[y * w + x] * m_gain + float(x - y);
}
