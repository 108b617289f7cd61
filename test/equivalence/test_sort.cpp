// std::sort in control functions on the GPU: a stable radix sort over records of any number of
// 32-bit words, keyed by a uint32_t, int or float field, ascending or descending. std::sort leaves
// the order of equal keys unspecified, so results are compared as sort results: the key sequence
// must equal the original's exactly, and each run of equal keys must hold the same records.
#include "Sorting.h"
#include "Sorting_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "Sorting_ISPC.h"
#endif
#include "Sorting_Vulkan.h"
#include "TestSupport.h"

#include <algorithm>
#include <functional>
#include <limits>
#include <random>
#include <tuple>

namespace {

// `got` is a valid sort of `expected`'s records: the same keys in the same order, and within each
// run of equal keys the same records. `less` orders whole records.
template <typename T, typename Key, typename Less>
void RequireSameSortResult(std::vector<T> got, std::vector<T> expected, Key key, Less less)
{
  REQUIRE(got.size() == expected.size());
  size_t keyMismatches = 0;
  for (size_t i = 0; i < got.size(); ++i) keyMismatches += !(key(got[i]) == key(expected[i]));
  REQUIRE(keyMismatches == 0);
  size_t recordMismatches = 0;
  for (size_t begin = 0; begin < got.size();)
  {
    size_t end = begin + 1;
    while (end < got.size() && key(expected[end]) == key(expected[begin])) ++end;
    std::sort(got.begin() + begin, got.begin() + end, less);
    std::sort(expected.begin() + begin, expected.begin() + end, less);
    for (size_t i = begin; i < end; ++i) recordMismatches += less(got[i], expected[i]) || less(expected[i], got[i]);
    begin = end;
  }
  REQUIRE(recordMismatches == 0);
}

bool CodeLess(LiteMath::uint2 a, LiteMath::uint2 b) { return std::tie(a.x, a.y) < std::tie(b.x, b.y); }
bool SampleLess(const Sample& a, const Sample& b) { return std::tie(a.weight, a.id, a.bucket) < std::tie(b.weight, b.id, b.bucket); }

std::vector<std::pair<const char*, std::shared_ptr<Sorting>>> Implementations(const std::shared_ptr<crossrt::VulkanContext>& ctx, int n)
{
  std::vector<std::pair<const char*, std::shared_ptr<Sorting>>> impls = {{"original", std::make_shared<Sorting>(n)},
                                                                         {"CPU", CreateSorting_CPU(n)}};
#ifdef CROSSRT_HAS_ISPC
  impls.push_back({"ISPC", CreateSorting_ISPC(n)});
#endif
  if (ctx) impls.push_back({"Vulkan", CreateSorting_Vulkan(ctx, n)});
  return impls;
}

}  // namespace

TEST_CASE("std::sort of key/value pairs by one field (LBVH's Morton codes) after a kernel", "[equivalence][sort]")
{
  auto ctx = ValidatedContext();
  for (int n : {1, 2, 1000, 4099, (1 << 18) + 5})
  {
    DYNAMIC_SECTION("n = " << n)
    {
      auto impls = Implementations(ctx, n);
      for (auto& [name, impl] : impls)
      {
        INFO(name);
        impl->CommitDeviceData();
        impl->SortCodes(n);
        RequireSameSortResult(impl->m_codes, impls[0].second->m_codes, [](LiteMath::uint2 c) { return c.x; }, CodeLess);
        if (n > 1000)  // the hashes repeat: equal keys really occur
          REQUIRE(std::adjacent_find(impl->m_codes.begin(), impl->m_codes.end(),
                                     [](LiteMath::uint2 a, LiteMath::uint2 b) { return a.x == b.x; }) != impl->m_codes.end());
      }
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("std::sort of records by a float field descending and an int field ascending", "[equivalence][sort]")
{
  auto ctx = ValidatedContext();
  for (int n : {3, 1025, 65537})
  {
    DYNAMIC_SECTION("n = " << n)
    {
      std::mt19937 rng(n);
      std::vector<Sample> samples(n);
      for (int i = 0; i < n; ++i)
      {
        // Negative and positive weights, both zeros, repeats; buckets across the sign boundary.
        float w = float(int(rng() % 2001) - 1000) * 0.125f;
        samples[i] = {i % 97 == 0 ? -0.0f : w, uint32_t(i), int(rng() % 64) - 32};
      }
      auto impls = Implementations(ctx, n);
      for (auto& [name, impl] : impls)
      {
        INFO(name);
        impl->m_samples = samples;
        impl->CommitDeviceData();
        impl->SortSamplesByWeight();
        RequireSameSortResult(impl->m_samples, impls[0].second->m_samples, [](const Sample& s) { return s.weight; }, SampleLess);
        REQUIRE(impl->m_samples.front().weight > impl->m_samples.back().weight);
      }
      for (auto& [name, impl] : impls)
      {
        INFO(name);
        impl->m_samples = samples;
        impl->CommitDeviceData();
        impl->SortSamplesByBucket();
        RequireSameSortResult(impl->m_samples, impls[0].second->m_samples, [](const Sample& s) { return s.bucket; }, SampleLess);
        REQUIRE(impl->m_samples.front().bucket < 0);
      }
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("std::sort with std::greater<int> and of floats without a comparator", "[equivalence][sort]")
{
  auto ctx = ValidatedContext();
  for (int n : {2, 5000, 200003})
  {
    DYNAMIC_SECTION("n = " << n)
    {
      std::mt19937 rng(n);
      std::vector<int> values(n);
      std::vector<float> floats(n);
      std::uniform_real_distribution<float> u(-1e30f, 1e30f);
      for (int i = 0; i < n; ++i)
      {
        values[i] = int(rng());  // the whole int range
        floats[i] = i % 5 == 0 ? u(rng) * 1e-40f : u(rng);  // denormals and zeros of both signs too
      }
      floats[0] = -std::numeric_limits<float>::infinity();
      floats[n - 1] = std::numeric_limits<float>::infinity();
      auto impls = Implementations(ctx, n);
      for (auto& [name, impl] : impls)
      {
        INFO(name);
        impl->m_values = values;
        impl->m_floats = floats;
        impl->CommitDeviceData();
        impl->SortValues();
        REQUIRE(impl->m_values == impls[0].second->m_values);
        REQUIRE(std::is_sorted(impl->m_values.rbegin(), impl->m_values.rend()));
        // Zeros of both signs compare equal, so only their run may be ordered differently.
        RequireSameSortResult(impl->m_floats, impls[0].second->m_floats, [](float f) { return f; }, std::less<float>());
        REQUIRE(std::is_sorted(impl->m_floats.begin(), impl->m_floats.end()));
      }
    }
  }
  RequireNoValidationMessages(ctx);
}
