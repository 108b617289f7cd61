// kernel_slicer's test 051: two kernels of one thread loop name their parameters alike
// (a_input2), but the per-thread function gives each another buffer. The GLSL megakernel binds
// buffers under their parameters' names, so this loop runs one dispatch per kernel (wavefront) in
// both execution modes; the ISPC thread loop names the second buffer apart.
#pragma once
#include <cstdint>

class SaxpyNames
{
public:
  virtual ~SaxpyNames() = default;
  virtual void SaxpyBlock(const float* a_adata, const float* a_bdata, const float* a_cdata, float* a_result, unsigned int a_size);
  virtual void CommitDeviceData() {}

protected:
  void Saxpy(const float* a_adata [[size("tid")]], const float* a_bdata [[size("tid")]], const float* a_cdata [[size("tid")]],
             float* a_result [[size("tid")]], unsigned int tid);
  void kernel_Mult(float* a_res, const float* a_input1, const float* a_input2, unsigned int tid);
  void kernel_Add(float* a_res, const float* a_input1, const float* a_input2, unsigned int tid);
};
