// A class with virtual control functions but no virtual destructor, as many are written.
#pragma once
#include "LiteMath.h"
#include <vector>
using LiteMath::float4;

class Brighten
{
public:
  virtual void Apply(int n, float4* a_pixels [[size("n")]]);
  virtual void CommitDeviceData() {}
  std::vector<float4> m_tint;

protected:
  void kernel1D_Apply(int n, float4* a_pixels);
};
