// A class with its own perspectiveMatrix beside `using namespace LiteMath;` (a helper name the
// translator's math library must not take from the user).
#pragma once
#include "LiteMath.h"
using namespace LiteMath;

float4x4 perspectiveMatrix(float fovy, float aspect, float zNear, float zFar);

class Projector
{
public:
  Projector();
  virtual void Project(int n, const float4* a_in [[size("n")]], float4* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}
  float4x4 m_proj;

protected:
  void kernel1D_Project(int n, const float4* a_in, float4* a_out);
};
