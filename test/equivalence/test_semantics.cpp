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
  CHECK(ref[5] == Approx(4.0f + 10.0f + 3.0f));  // the loop of two variables, the shadowing block's, 3e9 * 1e-9
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

TEST_CASE("Statements before a loop nest that set its locals reach every thread and the statements after it", "[equivalence]")
{
  auto ctx = ValidatedContext();
  const int n = 300;
  std::vector<float4> in(n);
  for (int i = 0; i < n; ++i)
    in[i] = float4(float(i % 7) - 3.0f, float(i % 5), 1.0f + float(i % 3), 1.0f);
  auto impls = AllImplementations(ctx);
  std::vector<std::vector<float>> results;
  for (auto& [name, impl] : impls)
  {
    INFO(name);
    impl->m_xf = translate4x4(float3(1.0f, 2.0f, 3.0f));
    impl->m_time = 2.0f;
    impl->CommitDeviceData();
    std::vector<float> out(n, -1.0f);
    impl->Transform(n, in.data(), out.data());
    impl->Transform(n, in.data(), out.data());
    results.push_back(out);
    // By hand: m(0, 3) = 0.5 replaces the translation's 1, column 1 is (0, 2, 0, 0), row 1 gains 0.25
    // in columns 0 and 1, and bias = 1 * m_time = 2.
    REQUIRE(impl->m_transforms == 2);
    REQUIRE(impl->m_corner == 0.5f + 0.25f + 2.0f);
    const float4 p = in[4];   // (1, 4, 2, 1)
    const float x = p.x + 0.5f, y = 0.25f * p.x + (2.0f + 0.25f) * p.y + 2.0f;
    REQUIRE(out[4] == Approx(x + 0.5f * y + 2.0f));
  }
  for (size_t k = 1; k < results.size(); ++k)
  {
    INFO(impls[k].first);
    REQUIRE(CountMismatches(results[0], results[k], 1e-5f) == 0);
  }
  RequireNoValidationMessages(ctx);
}
