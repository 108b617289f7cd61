#include "saxpy_names.h"

void SaxpyNames::SaxpyBlock(const float* a_adata, const float* a_bdata, const float* a_cdata, float* a_result, unsigned int a_size)
{
  for (unsigned int tid = 0; tid < a_size; tid++)
    Saxpy(a_adata, a_bdata, a_cdata, a_result, tid);
}

void SaxpyNames::Saxpy(const float* a_adata, const float* a_bdata, const float* a_cdata, float* a_result, unsigned int tid)
{
  float temp;
  kernel_Mult(&temp, a_adata, a_bdata, tid);   // a_input2 is a_bdata here
  kernel_Add(a_result, &temp, a_cdata, tid);   // and a_cdata here
}

void SaxpyNames::kernel_Mult(float* a_res, const float* a_input1, const float* a_input2, unsigned int tid) { *a_res = a_input1[tid] * a_input2[tid]; }

void SaxpyNames::kernel_Add(float* a_res, const float* a_input1, const float* a_input2, unsigned int tid) { a_res[tid] = *a_input1 + a_input2[tid]; }
