// Helpers defined only in the .cpp: a static function, a plain free function and a static member.
#pragma once
#include "LiteMath.h"
using namespace LiteMath;

class Tonemap
{
public:
  virtual void Apply(int w, int h, const float4* a_hdr [[size("w * h")]], float4* a_ldr [[size("w * h")]]);
  virtual void CommitDeviceData() {}
  float m_white = 4.0f;

protected:
  void kernel2D_Apply(int w, int h, const float4* a_hdr, float4* a_ldr);
  static float Luminance(float4 c);
};
