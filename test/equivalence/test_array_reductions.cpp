// Elements of a member array reduced in a kernel (coefs[k] += x, kernel_slicer's spherical
// harmonics): SphericalHarmonics_CPU reduces them in an OpenMP array section and gets the
// original's coefficients, to the float rounding of another summation order.
#include "SphericalHarmonics.h"
#include "SphericalHarmonics_CPU.h"
#include "TestSupport.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

TEST_CASE("Elements of a member array reduced in a kernel (coefs[k] += x) on the CPU backend", "[equivalence][reductions]")
{
  const uint32_t w = 96, h = 61;
  std::vector<uint32_t> texels(w * h);
  for (uint32_t i = 0; i < w * h; ++i)
    texels[i] = (i * 2654435761u) ^ (i >> 3);
  SphericalHarmonics original;
  original.Project(texels.data(), w, h);
  // The original, against the test's own sum of coefficient 0 (the mean colour times 4 pi).
  double red = 0.0;
  for (uint32_t t : texels)
    red += double(t & 0xFF) / 255.0;
  REQUIRE(original.coefs[0].x == Approx(4.0 * 3.14159265 * red / (w * h)).epsilon(1e-4));
  REQUIRE(original.m_texels == int(w * h));

  auto cpu = CreateSphericalHarmonics_CPU();
  for (int round = 0; round < 2; ++round)  // twice: the coefficients start again from zero
  {
    cpu->Project(texels.data(), w, h);
    REQUIRE(cpu->m_texels == int(w * h));
    for (int k = 0; k < SphericalHarmonics::kCoefficients; ++k)
    {
      INFO("coefficient " << k);
      for (int c = 0; c < 3; ++c)
        REQUIRE(cpu->coefs[k][c] == Approx(original.coefs[k][c]).margin(1e-5).epsilon(1e-4));
    }
  }
}
