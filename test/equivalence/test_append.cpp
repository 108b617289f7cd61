// push_back in kernels and indirect dispatch: the original class, Appending_CPU (appends under a
// lock on all cores) and Appending_Vulkan (an atomic counter, later kernels dispatched over the
// count the GPU holds) append the same elements. Threads append in any order, so the vectors are
// compared sorted; the outputs the indirectly dispatched kernel writes are compared exactly.
#include "Appending.h"
#include "Appending_CPU.h"
#include "Appending_Vulkan.h"
#ifdef CROSSRT_HAS_ISPC
#include "Appending_ISPC.h"
#endif
#include "TestSupport.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <tuple>

using demo::appends::Appending;
using demo::appends::Candidate;

namespace
{
std::vector<uint32_t> Sorted(std::vector<uint32_t> v)
{
  std::sort(v.begin(), v.end());
  return v;
}

std::vector<std::tuple<uint32_t, float>> Sorted(const std::vector<Candidate>& v)
{
  std::vector<std::tuple<uint32_t, float>> out;
  for (auto& c : v) out.emplace_back(c.index, c.value);
  std::sort(out.begin(), out.end());
  return out;
}

using Impls = std::vector<std::pair<const char*, std::shared_ptr<Appending>>>;

Impls AllBackends(const std::shared_ptr<crossrt::VulkanContext>& ctx, int capacity)
{
  Impls impls = {{"original", std::make_shared<Appending>(capacity)}, {"CPU", demo::appends::CreateAppending_CPU(capacity)}};
#ifdef CROSSRT_HAS_ISPC
  impls.push_back({"ISPC", demo::appends::CreateAppending_ISPC(capacity)});  // a gang's lanes at once, under the CPU class's lock
#endif
  if (ctx) impls.push_back({"Vulkan", demo::appends::CreateAppending_Vulkan(ctx, capacity)});
  return impls;
}
}  // namespace

TEST_CASE("push_back in a kernel, then kernels dispatched over the appended count", "[equivalence][append]")
{
  auto ctx = ValidatedContext();
  for (int n : {0, 1, 1000, 100003})
  {
    DYNAMIC_SECTION("n = " << n)
    {
      const auto values = RandomFloats(n, unsigned(n) + 1, -1.0f, 1.0f);
      std::vector<uint32_t> positive;
      std::vector<std::tuple<uint32_t, float>> large;
      std::vector<float> expectedOut(n, -7.0f);
      for (int i = 0; i < n; ++i)
      {
        if (values[i] > 0.0f) positive.push_back(uint32_t(i));
        if (values[i] > 0.5f)
        {
          large.emplace_back(uint32_t(i), 2.0f * values[i]);
          expectedOut[i] = 2.0f * values[i];
        }
      }
      if (n >= 1000) REQUIRE(large.size() > size_t(n) / 8);  // the data exercises every stage

      for (auto& [name, impl] : AllBackends(ctx, n))
      {
        INFO(name);
        std::vector<float> out(n, -7.0f);
        // Twice: the second call clears what the first appended, on the host and on the GPU.
        for (int call = 0; call < 2; ++call)
        {
          impl->Select(n, 0.5f, values.data(), out.data());
          REQUIRE(Sorted(impl->m_positive) == positive);
          REQUIRE(Sorted(impl->m_large) == large);
          REQUIRE(out == expectedOut);
        }
        REQUIRE(impl->m_positive.capacity() == size_t(n));  // read back without reallocating
      }
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Appends accumulate across calls when the control function does not clear", "[equivalence][append]")
{
  auto ctx = ValidatedContext();
  const int n = 5003;
  const auto first = RandomFloats(n, 11, -1.0f, 1.0f), second = RandomFloats(n, 12, -1.0f, 1.0f);
  std::vector<uint32_t> expected;
  for (auto* values : {&first, &second})
    for (int i = 0; i < n; ++i)
      if ((*values)[i] < 0.0f) expected.push_back(uint32_t(i));
  std::sort(expected.begin(), expected.end());
  for (auto& [name, impl] : AllBackends(ctx, n))
  {
    INFO(name);
    std::vector<uint32_t> room(4, 0u);
    impl->Room(4, room.data());
    REQUIRE(room == std::vector<uint32_t>(4, uint32_t(2 * n)));  // capacity() and size() in a kernel
    impl->Collect(n, first.data());
    const size_t afterFirst = impl->m_negative.size();
    impl->Room(4, room.data());
    REQUIRE(room == std::vector<uint32_t>(4, uint32_t(2 * n - afterFirst)));
    impl->Collect(n, second.data());
    REQUIRE(afterFirst > 0);
    REQUIRE(Sorted(impl->m_negative) == expected);
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Sorting appended vectors in the control function that appends to them", "[equivalence][append][sort]")
{
  auto ctx = ValidatedContext();
  for (int n : {0, 1, 1000, 100003})
  {
    DYNAMIC_SECTION("n = " << n)
    {
      // Distinct values in random places, so that every backend must give one order: random
      // floats repeat at this many draws.
      std::vector<float> values(n);
      std::vector<int> places(n);
      std::iota(places.begin(), places.end(), 0);
      std::shuffle(places.begin(), places.end(), std::mt19937(unsigned(n) + 7));
      for (int i = 0; i < n; ++i) values[places[i]] = -1.0f + 2.0f * (float(i) + 0.5f) / float(n);
      std::vector<uint32_t> positive;
      std::vector<std::pair<float, uint32_t>> large;  // (2 * value, index)
      for (int i = 0; i < n; ++i)
      {
        if (values[i] > 0.0f) positive.push_back(uint32_t(i));
        if (values[i] > 0.5f) large.emplace_back(2.0f * values[i], uint32_t(i));
      }
      std::sort(positive.rbegin(), positive.rend());
      std::sort(large.begin(), large.end());
      REQUIRE(std::adjacent_find(large.begin(), large.end(), [](auto& a, auto& b) { return a.first == b.first; }) == large.end());
      std::vector<float> expectedRanks(n, -1.0f);
      for (size_t r = 0; r < large.size(); ++r) expectedRanks[large[r].second] = float(r);

      for (auto& [name, impl] : AllBackends(ctx, n))
      {
        INFO(name);
        for (int call = 0; call < 2; ++call)
        {
          std::vector<float> ranks(n, -1.0f);
          impl->SelectSorted(n, 0.5f, values.data(), ranks.data());
          REQUIRE(impl->m_positive == positive);
          REQUIRE(impl->m_large.size() == large.size());
          for (size_t r = 0; r < large.size(); ++r)
          {
            REQUIRE(impl->m_large[r].value == large[r].first);
            REQUIRE(impl->m_large[r].index == large[r].second);
          }
          REQUIRE(ranks == expectedRanks);
        }
      }
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("push_back in helpers and in a kernel_ function whose loop is in the control function", "[equivalence][append]")
{
  auto ctx = ValidatedContext();
  for (int n : {0, 1, 20011})
  {
    DYNAMIC_SECTION("n = " << n)
    {
      const auto values = RandomFloats(n, unsigned(n) + 3, -1.0f, 1.0f);
      std::vector<uint32_t> small;
      std::vector<std::tuple<uint32_t, float>> tagged;
      for (int i = 0; i < n; ++i)
      {
        if (std::abs(values[i]) < 0.1f) small.push_back(uint32_t(i));
        if (values[i] > 0.9f) tagged.emplace_back(uint32_t(i), values[i]);
      }
      if (n > 1000) REQUIRE((small.size() > size_t(n) / 20 && tagged.size() > size_t(n) / 40));
      for (auto& [name, impl] : AllBackends(ctx, n))
      {
        INFO(name);
        for (int call = 0; call < 2; ++call)
        {
          impl->Classify(n, values.data());
          REQUIRE(Sorted(impl->m_small) == small);
          REQUIRE(Sorted(impl->m_tagged) == tagged);
        }
      }
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Appending past the capacity: the GPU keeps the capacity and says so", "[equivalence][append]")
{
  auto ctx = ValidatedContext();
  if (!ctx) return;
  const int n = 1000, capacity = 10;
  const auto values = RandomFloats(n, 5, -1.0f, 1.0f);
  std::vector<float> out(n, -7.0f);
  auto gpu = demo::appends::CreateAppending_Vulkan(ctx, capacity);
  REQUIRE_THROWS_WITH(gpu->Select(n, 0.5f, values.data(), out.data()),
                      Catch::Contains("Appending::m_positive") && Catch::Contains("capacity is 10") &&
                          Catch::Contains("reserve("));
  // What fits is kept: every kept index is one of the positive values.
  REQUIRE(gpu->m_positive.size() == size_t(capacity));
  for (uint32_t i : gpu->m_positive) REQUIRE(values[i] > 0.0f);
  // The original grows the vector instead: it has no capacity limit.
  Appending original(capacity);
  original.Select(n, 0.5f, values.data(), out.data());
  REQUIRE(original.m_positive.size() > size_t(capacity));
  // After reserving enough, the GPU version agrees again.
  gpu->m_positive.reserve(n);
  gpu->m_large.reserve(n);
  std::vector<float> gpuOut(n, -7.0f), cpuOut(n, -7.0f);
  gpu->Select(n, 0.5f, values.data(), gpuOut.data());
  original.Select(n, 0.5f, values.data(), cpuOut.data());
  REQUIRE(Sorted(gpu->m_positive) == Sorted(original.m_positive));
  REQUIRE(gpuOut == cpuOut);
  RequireNoValidationMessages(ctx);
}
