// std::vector locals of a control function passed between its kernels (kernel_slicer's 048/049
// saxpy samples): zero-filled, filled with a value, passed with an offset, asked for their size.
#pragma once
#include <cstdint>
#include <vector>

class StagedSaxpy
{
public:
  StagedSaxpy() {}
  virtual ~StagedSaxpy() {}
  // a_out[i] = a_x[i] * a_y[i] + 2 (through three temporary vectors).
  virtual void Run(const float* a_x [[size("n")]], const float* a_y [[size("n")]], float* a_out [[size("n")]], uint32_t n);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Mult(float* a_res, const float* a_in1, const float* a_in2, uint32_t a_size);
  void kernel1D_Add(float* a_res, const float* a_in1, const float* a_in2, uint32_t a_size);
};
