// Three things kernel_slicer's samples write that the ISPC backend once printed as code ISPC does
// not compile: one thread writing elements at constant indices (`if (i == 0) a_out[0] = v.x;`, its
// test of constructors; here also into a member vector, with += and std::min, and through row
// pointers, one every thread shares and one per thread), a const local with a constant value in a
// cast (`float(numSamples)`, its shadow sample), and a helper's `const float lo[3]` given a const
// local struct's array field (its BVH walk).
#pragma once
#include "LiteMath.h"

#include <vector>

struct Slab
{
  float lo[3];
  float hi[3];
};

class FirstThread
{
public:
  FirstThread();
  virtual ~FirstThread() = default;
  virtual void Run(int n, const float* a_in [[size("n")]], float* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}

  std::vector<float> m_firsts;  // written by the first thread only, at constant indices

protected:
  void kernel1D_Run(int n, const float* a_in, float* a_out);
  std::vector<Slab> m_slabs;
};
