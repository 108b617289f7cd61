// kernel_slicer's RTV form: a per-thread function calls kernels with the addresses of its locals,
// and a ...Block control function runs it over all threads.
#pragma once
#include "LiteMath.h"
#include <cstdint>

class SaxpyBlock
{
public:
  virtual void RunBlock(uint32_t n, float a, const float* x [[size("n")]], const float* y [[size("n")]], float* out [[size("n")]]);
  virtual void CommitDeviceData() {}

protected:
  void Run(uint32_t tid, float a, const float* x, const float* y, float* out);  // one thread's work
  void kernel_Mul(uint32_t tid, float a, const float* x, float* temp);
  void kernel_Add(uint32_t tid, const float* temp, const float* y, float* out);
};
