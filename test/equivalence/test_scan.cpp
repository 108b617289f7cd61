// Library calls in control functions on the GPU: std::exclusive_scan and std::inclusive_scan
// (one to three scan levels, sizes that are not powers of two), std::fill and memcpy, checked
// against the original class and Compaction_CPU. Integer results exactly; the float prefix sum
// within 1e-4 relative plus 1e-3 absolute (the GPU adds in a tree order, the CPU left to right).
#include "Compaction.h"
#include "Compaction_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "Compaction_ISPC.h"
#endif
#include "Compaction_Vulkan.h"
#include "TestSupport.h"

#include <algorithm>
#include <random>

TEST_CASE("Stream compaction: a kernel, std::exclusive_scan, a kernel", "[equivalence][scan]")
{
  auto ctx = ValidatedContext();
  for (int n : {1, 1000, 1025, 70001, (1 << 20) + 7})
  {
    DYNAMIC_SECTION("n = " << n)
    {
      std::mt19937 rng(n);
      std::uniform_real_distribution<float> u(-1.0f, 1.0f);
      std::vector<float> values(n);
      for (auto& v : values) v = u(rng);
      std::vector<std::pair<const char*, std::shared_ptr<Compaction>>> impls = {
          {"original", std::make_shared<Compaction>(n)}, {"CPU", CreateCompaction_CPU(n)}};
#ifdef CROSSRT_HAS_ISPC
      impls.push_back({"ISPC", CreateCompaction_ISPC(n)});
#endif
      if (ctx) impls.push_back({"Vulkan", CreateCompaction_Vulkan(ctx, n)});
      std::vector<float> expected;
      for (float v : values)
        if (v > 0.0f) expected.push_back(v);
      for (auto& [name, impl] : impls)
      {
        INFO(name);
        std::vector<float> out(n, -5.0f);
        impl->CommitDeviceData();
        impl->Compact(n, values.data(), out.data());
        REQUIRE(impl->m_kept == expected.size());
        REQUIRE(std::equal(expected.begin(), expected.end(), out.begin()));
        REQUIRE(impl->m_slot == impls[0].second->m_slot);  // the scanned member vector came back
      }
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("std::inclusive_scan of floats, memcpy and std::fill in a control function", "[equivalence][scan]")
{
  auto ctx = ValidatedContext();
  for (int n : {3, 4097, 300007})
  {
    DYNAMIC_SECTION("n = " << n)
    {
      std::vector<float> values(n);
      for (int i = 0; i < n; ++i) values[i] = float((i * 7919) % 13) * 0.25f - 1.0f;
      std::vector<std::pair<const char*, std::shared_ptr<Compaction>>> impls = {
          {"original", std::make_shared<Compaction>(n)}, {"CPU", CreateCompaction_CPU(n)}};
#ifdef CROSSRT_HAS_ISPC
      impls.push_back({"ISPC", CreateCompaction_ISPC(n)});
#endif
      if (ctx) impls.push_back({"Vulkan", CreateCompaction_Vulkan(ctx, n)});
      double running = 0.0;
      std::vector<float> exact(n);
      for (int i = 0; i < n; ++i) exact[i] = float(running += values[i]);
      for (auto& [name, impl] : impls)
      {
        INFO(name);
        std::vector<float> prefix(n), copy(n, 0.0f);
        impl->CommitDeviceData();
        impl->PrefixSum(n, values.data(), prefix.data(), copy.data());
        size_t bad = 0;
        for (int i = 0; i < n; ++i) bad += !(std::fabs(prefix[i] - exact[i]) <= 1e-4f * std::fabs(exact[i]) + 1e-3f);  // NaN counts
        REQUIRE(bad == 0);
        REQUIRE(copy == values);
        REQUIRE(std::all_of(impl->m_marks.begin(), impl->m_marks.end(), [](int m) { return m == 7; }));
      }
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("std::sort of uint32_t keys in a control function becomes a GPU radix sort", "[equivalence][sort]")
{
  auto ctx = ValidatedContext();
  for (int n : {1, 2, 1000, 1025, 100003, (1 << 20) + 3})
  {
    DYNAMIC_SECTION("n = " << n)
    {
      std::vector<std::pair<const char*, std::shared_ptr<Compaction>>> impls = {
          {"original", std::make_shared<Compaction>(n)}, {"CPU", CreateCompaction_CPU(n)}};
#ifdef CROSSRT_HAS_ISPC
      impls.push_back({"ISPC", CreateCompaction_ISPC(n)});
#endif
      if (ctx) impls.push_back({"Vulkan", CreateCompaction_Vulkan(ctx, n)});
      for (auto& [name, impl] : impls)
      {
        INFO(name);
        uint32_t state = uint32_t(n);
        for (int i = 0; i < n; ++i)
        {
          impl->m_slot[i] = (state = state * 1664525u + 1013904223u);  // full 32-bit keys
          impl->m_keep[i] = state >> 29;                                 // many equal keys
        }
        impl->CommitDeviceData();
        impl->SortSlots(n);
        REQUIRE(std::is_sorted(impl->m_slot.begin(), impl->m_slot.end()));
        REQUIRE(std::is_sorted(impl->m_keep.begin(), impl->m_keep.end()));
        REQUIRE(impl->m_slot == impls[0].second->m_slot);
        REQUIRE(impl->m_keep == impls[0].second->m_keep);
      }
    }
  }
  RequireNoValidationMessages(ctx);
}
