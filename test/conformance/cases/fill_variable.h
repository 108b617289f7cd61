// A struct passed by value to a kernel and used in it (kernel_slicer's 020 and 032).
#pragma once
#include "LiteMath.h"

struct Variable
{
  unsigned offset;
  float scale;
};

struct BoxHit
{
  unsigned id;
  float t;
};

static inline BoxHit make_BoxHit(unsigned id, float t)
{
  BoxHit res;
  res.id = id;
  res.t = t;
  return res;
}

class FillVariable
{
public:
  virtual void Fill(float* a_data [[size("a_size")]], unsigned a_size, BoxHit* a_hits [[size("a_steps")]], unsigned a_steps);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Fill(float* data, unsigned steps, Variable A, float val);
  void kernel1D_Hits(BoxHit* a_hits, unsigned a_steps, Variable A);
};
