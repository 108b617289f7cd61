#include "fill_variable.h"

void FillVariable::Fill(float* a_data, unsigned a_size, BoxHit* a_hits, unsigned a_steps)
{
  Variable a;
  a.offset = a_size - a_steps;
  a.scale = 3.0f;
  kernel1D_Fill(a_data, a_steps, a, 2.0f);
  kernel1D_Hits(a_hits, a_steps, a);
}

void FillVariable::kernel1D_Fill(float* data, unsigned steps, Variable A, float val)
{
  for (unsigned i = 0; i < steps; i++)
    data[A.offset + i] = val * A.scale + float(i);
}

void FillVariable::kernel1D_Hits(BoxHit* a_hits, unsigned a_steps, Variable A)
{
  for (unsigned i = 0; i < a_steps; i++)
    a_hits[i] = make_BoxHit(i + A.offset, A.scale * float(i));
}
