// kernel_slicer's test 002 form: the control function's pointers carry no size annotation; each is
// handed straight to a kernel1D_ whose loop reads or writes it only at its own index, so the loop's
// bound is the size (n elements for `i < n`, n + 1 for `i <= n`).
#pragma once
#include <cstdint>

class LoopSized
{
public:
  virtual ~LoopSized() = default;
  virtual void Sum(const int* a_data, unsigned int a_last);                 // reads a_data[0..a_last]
  virtual void Scale(const float* a_in, float* a_out, uint32_t a_count);   // a_count elements each
  virtual void CommitDeviceData() {}

  void kernel1D_Sum(const int* a_data, unsigned int a_last);
  void kernel1D_Scale(const float* a_in, float* a_out, uint32_t a_count);
  int m_sum = 0;
  float m_factor = 1.5f;
};
