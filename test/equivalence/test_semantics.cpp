// C++ semantics the generated GPU and CPU code must keep, each compared with the original class
// (expected values also checked by hand where they are simple). Per-element tolerance 1e-5
// relative: the GPU may fuse multiply-adds.
#include "Semantics.h"
#include "Semantics_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "Semantics_ISPC.h"
#endif
#include "Semantics_Vulkan.h"
#include "TestSupport.h"

namespace {
// The original class, Semantics_CPU, Semantics_ISPC where ISPC is found and, when a Vulkan device exists, Semantics_Vulkan.
std::vector<std::pair<const char*, std::shared_ptr<Semantics>>> AllImplementations(const std::shared_ptr<crossrt::VulkanContext>& ctx)
{
  std::vector<std::pair<const char*, std::shared_ptr<Semantics>>> impls = {{"original", std::make_shared<Semantics>()},
                                                                          {"CPU", CreateSemantics_CPU()}};
#ifdef CROSSRT_HAS_ISPC
  impls.push_back({"ISPC", CreateSemantics_ISPC()});
#endif
  if (ctx) impls.push_back({"Vulkan", CreateSemantics_Vulkan(ctx)});
  return impls;
}
}  // namespace

TEST_CASE("Matrices, double promotions, remainders, rounding, initialisers and struct members keep C++ semantics", "[equivalence]")
{
  auto ctx = ValidatedContext();
  const int n = 40;
  auto impls = AllImplementations(ctx);
  std::vector<std::vector<float>> results;
  for (auto& [name, impl] : impls)
  {
    std::vector<float> out(n * 8, -1.0f);
    impl->Evaluate(n, out.data());
    results.push_back(out);
  }
  const auto& ref = results[0];
  // By hand, for i = 0 (x = -10): the matrix rows apply as written.
  CHECK(ref[0] == Approx((1 * -10 + 2 * 1 + 3 * 2 + 4) + 0.5 * (5 * -10 + 6 + 7 * 2 + 8)));
  CHECK(ref[1] == -2.0f);           // (0 - 7) % 5 in C++
  CHECK(ref[2] == -5.0f);           // round(-5.0)
  CHECK(ref[8 * 1 + 2] == -5.0f);   // round(-4.5) = -5 (away from zero)
  CHECK(ref[8 * 3 + 2] == -4.0f);   // round(-3.5) = -4
  CHECK(ref[3] == Approx(3.5f - 4.0f / 3.0f));
  CHECK(ref[4] == Approx(0.25f + 8.0f + 1.5f));
  CHECK(ref[5] == Approx(4.0f + 3.0f));
  CHECK(ref[6] == 7.0f);
  CHECK(ref[7] == 1.0f);
  for (size_t k = 1; k < results.size(); ++k)
  {
    INFO(impls[k].first);
    for (int i = 0; i < n * 8; ++i)
    {
      INFO("element " << i);
      REQUIRE(Close(ref[i], results[k][i], 1e-5f));
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Members changed between kernels, and RTV loops inside host loops, run in C++ order", "[equivalence]")
{
  auto ctx = ValidatedContext();
  const int n = 1000;
  auto impls = AllImplementations(ctx);
  std::vector<std::vector<float>> results;
  for (auto& [name, impl] : impls)
  {
    std::vector<float> out(n, 0.0f);
    impl->m_time = 0.5f;
    impl->Steps(n, 5, out.data());
    results.push_back(out);
    INFO(name);
    REQUIRE(impl->m_time == 0.5f + 5.0f + 3.0f);
  }
  for (size_t k = 1; k < results.size(); ++k)
  {
    INFO(impls[k].first);
    REQUIRE(CountMismatches(results[0], results[k], 1e-5f) == 0);
  }
  RequireNoValidationMessages(ctx);
}
