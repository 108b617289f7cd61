// An append kernel whose loop is preceded by emptying the vector and followed by writing its size.
#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <vector>

struct Kept
{
  uint32_t index;
  float value;
};

class KeepPositive
{
public:
  KeepPositive() { m_kept.reserve(4096); }
  virtual void Filter(uint32_t n, const float* a_values [[size("n")]], uint32_t* a_count [[size("1")]]);
  virtual void CommitDeviceData() {}
  std::vector<Kept> m_kept;

protected:
  void kernel1D_Filter(uint32_t n, const float* a_values, uint32_t* a_count);
};
