#include "staged_saxpy.h"

void StagedSaxpy::Run(const float* a_x, const float* a_y, float* a_out, uint32_t n)
{
  std::vector<float> product(n);
  std::vector<float> twos(n, 2.0f);
  std::vector<float> both(2 * n);  // the first half stays zero
  kernel1D_Mult(product.data(), a_x, a_y, n);
  kernel1D_Add(both.data() + n, product.data(), twos.data(), uint32_t(twos.size()));
  kernel1D_Add(a_out, both.data() + n, both.data(), n);
}

void StagedSaxpy::kernel1D_Mult(float* a_res, const float* a_in1, const float* a_in2, uint32_t a_size)
{
  for (uint32_t i = 0; i < a_size; i++)
    a_res[i] = a_in1[i] * a_in2[i];
}

void StagedSaxpy::kernel1D_Add(float* a_res, const float* a_in1, const float* a_in2, uint32_t a_size)
{
  for (uint32_t i = 0; i < a_size; i++)
    a_res[i] = a_in1[i] + a_in2[i];
}
