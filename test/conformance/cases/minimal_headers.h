// A header that includes only what the class itself needs: the generated code brings its own
// standard headers (offsetof, std::min, memcpy, std::vector, std::shared_ptr...).
#pragma once
#include "LiteMath.h"
#include <vector>

class Decay
{
public:
  virtual void Run(int n, float* a_values [[size("n")]]);
  virtual void CommitDeviceData() {}
  std::vector<float> m_rates;
  float m_floor = 0.125f;

protected:
  void kernel1D_Run(int n, float* a_values);
};
