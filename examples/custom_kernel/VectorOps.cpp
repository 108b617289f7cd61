#include "VectorOps.h"

void VectorOps::Process(int n, float* data)
{
  kernel1D_Scale(n, m_factor, data);
  kernel1D_Offset(n, data);
}

void VectorOps::kernel1D_Scale(int n, float factor, float* data)
{
  for (int i = 0; i < n; i++)
    data[i] = data[i] * factor;
}

void VectorOps::kernel1D_Offset(int n, float* data)
{
  for (int i = 0; i < n; i++)
    data[i] = data[i] + m_offset;
}
