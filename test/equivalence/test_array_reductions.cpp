// Elements of a member array reduced in a kernel (coefs[k] += x, kernel_slicer's spherical
// harmonics) on every backend: SphericalHarmonics_CPU reduces them in an OpenMP array section,
// _Vulkan and _ISPC in an array a thread (a lane) and a partial result per element and workgroup
// (chunk). Each gets the original's coefficients, to the float rounding of another summation order.
#include "SphericalHarmonics.h"
#include "SphericalHarmonics_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "SphericalHarmonics_ISPC.h"
#endif
#include "SphericalHarmonics_Vulkan.h"
#include "TestSupport.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

TEST_CASE("Elements of a member array reduced in a kernel (coefs[k] += x) on every backend", "[equivalence][reductions]")
{
  const uint32_t w = 96, h = 61;  // 5856 texels: 23 workgroups of 256 on the GPU
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

  // Coefficients near zero are sums that cancel: each is compared within a part of the largest, 1e-4
  // on the CPU backends (which sum in another order). On the GPU, 2e-3: Vulkan lets sin and cos be
  // 2^-11 off, and lavapipe's are (coefficient 6, whose basis function is 3 z^2 - 1, sits 2e-4 of
  // the largest off on it, the same in all three channels); the conformance case element_totals,
  // which takes no sines, agrees within 1e-6 there.

  float scale = 0.0f;
  for (auto& c : original.coefs) scale = std::max({scale, std::abs(c.x), std::abs(c.y), std::abs(c.z)});
  REQUIRE(scale > 0.1f);

  auto ctx = ValidatedContext();
  std::vector<std::pair<const char*, std::shared_ptr<SphericalHarmonics>>> impls = {{"CPU", CreateSphericalHarmonics_CPU()}};
#ifdef CROSSRT_HAS_ISPC
  impls.push_back({"ISPC", CreateSphericalHarmonics_ISPC()});
#endif
  if (ctx) impls.push_back({"Vulkan", CreateSphericalHarmonics_Vulkan(ctx)});
  for (auto& [name, impl] : impls)
    for (int round = 0; round < 2; ++round)  // twice: the coefficients start again from zero
    {
      INFO(name << ", round " << round);
      impl->Project(texels.data(), w, h);
      REQUIRE(impl->m_texels == int(w * h));
      for (int k = 0; k < SphericalHarmonics::kCoefficients; ++k)
      {
        INFO("coefficient " << k << ": " << impl->coefs[k].x << " " << impl->coefs[k].y << " " << impl->coefs[k].z << ", the original's "
                              << original.coefs[k].x << " " << original.coefs[k].y << " " << original.coefs[k].z);
        for (int c = 0; c < 3; ++c)
          REQUIRE(std::abs(impl->coefs[k][c] - original.coefs[k][c]) <= (std::string(name) == "Vulkan" ? 2e-3f : 1e-4f) * scale);
      }
    }
  RequireNoValidationMessages(ctx);
}
