// A pointer to a row of a buffer, indexed in the kernel: const float* row = a_in + y * w.
#pragma once
#include "LiteMath.h"

class RowSums
{
public:
  virtual void Sum(int w, int h, const float* a_in [[size("w", "h")]], float* a_sums [[size("h")]]);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Rows(int w, int h, const float* a_in, float* a_sums);
};
