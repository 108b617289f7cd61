// Several strings in a size annotation multiply: size("w", "h") is w * h elements (kernel_slicer's form).
#pragma once
#include "LiteMath.h"
using namespace LiteMath;

class ImageScale
{
public:
  ImageScale() {}
  virtual void Scale(int w, int h, const float* a_in __attribute__((size("w", "h"))), float* a_out __attribute__((size("w", "h"))));
  virtual void CommitDeviceData() {}
  virtual void GetExecutionTime(const char*, float[4]) {}

protected:
  virtual void kernel2D_Scale(int w, int h, const float* a_in, float* a_out);
  float m_gain = 2.5f;
};
