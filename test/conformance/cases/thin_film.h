// LiteMath::complex in kernels: a thin-film Fresnel term computed with complex arithmetic.
#pragma once
#include "LiteMath.h"
using LiteMath::complex;
using LiteMath::M_PI;

class ThinFilm
{
public:
  virtual void Reflectance(int n, const float* a_cosTheta [[size("n")]], float* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}
  float m_eta = 1.33f, m_thickness = 400.0f, m_lambda = 550.0f;

protected:
  void kernel1D_Reflectance(int n, const float* a_cosTheta, float* a_out);
};
