// Elements of a member array reduced in a kernel, as kernel_slicer's spherical-harmonics sample
// writes them (coefs[0] += color; ... coefs[8] += ...), in a 2D loop nest: every backend reduces
// them (test/equivalence/test_array_reductions.cpp).
#pragma once
#include "LiteMath.h"

#include <cstdint>

class SphericalHarmonics
{
public:
  static constexpr int kCoefficients = 9;

  virtual ~SphericalHarmonics() = default;
  // Projects an RGBA8 environment map (a_width x a_height, latitude rows) onto 9 SH coefficients.
  virtual void Project(const uint32_t* a_data __attribute__((size("a_width", "a_height"))), uint32_t a_width, uint32_t a_height);
  virtual void CommitDeviceData() {}

  LiteMath::float3 coefs[kCoefficients];
  int m_texels = 0;  // a whole member reduced beside them

protected:
  virtual void kernel2D_Project(const uint32_t* a_data, uint32_t a_width, uint32_t a_height);

private:
  // Private constants the kernel reads, in its loop and after it (the generated class derives from
  // this one: it gets their values).
  static constexpr float    PI       = 3.14159265358979323846f;
  static constexpr uint32_t kOneTexel = 1u;
};
