// A member vector's data() inside a kernel, and a pointer into it (data() + k) handed to a helper.
#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <vector>

class Gather
{
public:
  Gather();
  virtual void Run(uint32_t n, float* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}
  std::vector<float> m_table;
  std::vector<uint32_t> m_indices;

protected:
  void kernel1D_Run(uint32_t n, float* a_out);
  float Lookup(uint32_t a_id) const;
};
