// The paper's include spelling "Image2d.h", and an Image2D member read by a 2D kernel.
#pragma once
#include "LiteMath.h"
#include "Image2d.h"
using LiteImage::Image2D;
using LiteMath::float4;
using LiteMath::int2;

class BoxBlur
{
public:
  BoxBlur(int w, int h);
  virtual void Blur(int w, int h, float4* a_out [[size("w", "h")]]);
  virtual void CommitDeviceData() {}
  Image2D<float4> m_image;

protected:
  void kernel2D_Blur(int w, int h, float4* a_out);
};
