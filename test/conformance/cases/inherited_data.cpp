#include "inherited_data.h"

void BaseBlend::Test(float* a_data, unsigned int a_size) { kernel1D_Test(a_data, a_size); }

void BaseBlend::kernel1D_Test(float* a_data, unsigned int a_size)
{
  for (unsigned i = 0; i < a_size; i++)
    a_data[i] = dataInBaseClass;
}

void DerivedBlend::Init()
{
  for (unsigned i = 0; i < 16; i++)
  {
    vInBase[i] = float(i);
    vInDerived[i] = float(16 - i);
  }
}

void DerivedBlend::kernel1D_Test(float* a_data, unsigned int a_size)
{
  for (unsigned i = 0; i < a_size; i++)
    a_data[i] = dataInBaseClass * vInBase[i % 16] + dataInDerivedClass * vInDerived[i % 16];
}
