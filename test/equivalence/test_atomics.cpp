// crossrt::Atomic* in kernels: the original class (one thread), AtomicCounters_CPU (all cores,
// __atomic builtins) and AtomicCounters_Vulkan (GLSL atomics on coherent buffers) agree. The
// expected values are computed here from the keys, not by the class. Which thread claims a bin
// first is up to the scheduler, so claims are checked for being valid, not equal.
#include "AtomicCounters.h"
#include "AtomicCounters_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "AtomicCounters_ISPC.h"
#endif
#include "AtomicCounters_Vulkan.h"
#include "TestSupport.h"

#include <cmath>
#include <limits>
#include <numeric>

namespace
{
using Impls = std::vector<std::pair<const char*, std::shared_ptr<AtomicCounters>>>;

Impls AllBackends(const std::shared_ptr<crossrt::VulkanContext>& ctx, int bins, int maxLeaves)
{
  Impls impls = {{"original", std::make_shared<AtomicCounters>(bins, maxLeaves)},
                 {"CPU", CreateAtomicCounters_CPU(bins, maxLeaves)}};
#ifdef CROSSRT_HAS_ISPC
  impls.push_back({"ISPC", CreateAtomicCounters_ISPC(bins, maxLeaves)});  // ISPC's global atomics
#endif
  if (ctx) impls.push_back({"Vulkan", CreateAtomicCounters_Vulkan(ctx, bins, maxLeaves)});
  return impls;
}

std::vector<uint32_t> RandomKeys(int n, unsigned seed)
{
  std::mt19937 rng(seed);
  std::vector<uint32_t> keys(n);
  for (auto& k : keys) k = rng() | 0x100u;  // bit 8 in every key: the AND keeps it
  return keys;
}
}  // namespace

TEST_CASE("Atomics in kernels: counts, claims, bit masks and extremes agree on every backend", "[equivalence][atomics]")
{
  auto ctx = ValidatedContext();
  const int bins = 37;
  for (int n : {0, 1, 1000, 100003})
  {
    DYNAMIC_SECTION("n = " << n)
    {
      const auto keys = RandomKeys(n, unsigned(n) + 7);
      std::vector<uint32_t> counts(bins, 0);
      std::vector<int32_t> residues(4, 5);
      uint32_t orAll = 0, andAll = 0xFFFFFFFFu, xorAll = 0, smallest = 0xFFFFFFFFu, largest = 0;
      for (uint32_t k : keys)
      {
        counts[k % bins]++;
        residues[k % 4]++;
        orAll |= k, andAll &= k, xorAll ^= k;
        smallest = std::min(smallest, k), largest = std::max(largest, k);
      }
      if (n >= 1000) REQUIRE(std::count(counts.begin(), counts.end(), 0u) == 0);  // every bin is contended

      for (auto& [name, impl] : AllBackends(ctx, bins, 1))
      {
        INFO(name);
        std::vector<int32_t> perResidue(4, 5);
        impl->Count(n, keys.data(), perResidue.data());
        REQUIRE(impl->m_bins == counts);
        REQUIRE(perResidue == residues);
        REQUIRE(impl->m_masks == std::vector<uint32_t>{orAll, andAll, xorAll});
        REQUIRE(impl->m_smallest == smallest);
        REQUIRE(impl->m_largest == largest);
        for (int b = 0; b < bins; ++b)
        {
          INFO("bin " << b);
          if (counts[b] == 0)
          {
            REQUIRE(impl->m_owner[b] == AtomicCounters::kNobody);
            REQUIRE(impl->m_last[b] == AtomicCounters::kNobody);
            continue;
          }
          REQUIRE(impl->m_owner[b] < uint32_t(n));
          REQUIRE(keys[impl->m_owner[b]] % bins == uint32_t(b));
          REQUIRE(impl->m_last[b] < uint32_t(n));
          REQUIRE(keys[impl->m_last[b]] % bins == uint32_t(b));
        }
      }
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Atomics in kernels: a bottom-up tree pass where the second child to arrive finishes its parent", "[equivalence][atomics]")
{
  auto ctx = ValidatedContext();
  const int maxLeaves = 70001;
  auto backends = AllBackends(ctx, 1, maxLeaves);
  for (int leaves : {1, 2, 3, 1000, 70001})
  {
    DYNAMIC_SECTION("leaves = " << leaves)
    {
      const auto values = RandomKeys(leaves, unsigned(leaves));
      // The sums from the leaves up, in wrapping uint32 arithmetic as the kernel adds.
      std::vector<uint32_t> sums(2 * size_t(leaves) - 1);
      for (int leaf = 0; leaf < leaves; ++leaf) sums[leaves - 1 + leaf] = values[leaf];
      for (int k = leaves - 2; k >= 0; --k) sums[k] = sums[2 * k + 1] + sums[2 * k + 2];
      REQUIRE(sums[0] == std::accumulate(values.begin(), values.end(), 0u));

      for (auto& [name, impl] : backends)
      {
        INFO(name);
        // Twice: the counters are cleared by the call itself.
        for (int call = 0; call < 2; ++call)
        {
          impl->SumTree(leaves, values.data());
          const std::vector<uint32_t> got(impl->m_treeSums.begin(), impl->m_treeSums.begin() + sums.size());
          REQUIRE(got == sums);
          // Every inner node was reached by both children.
          for (int k = 0; k < leaves - 1; ++k) REQUIRE(impl->m_arrivals[k] == 2u);
        }
      }
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("LiteMath's ReduceAdd and InterlockedAdd3f: float sums into a member vector and an array agree on every backend", "[equivalence][atomics]")
{
  auto ctx = ValidatedContext();
  const int n = 5000, cells = 37;
  // Multiples of 1/8 below 2^10: every partial sum is exact, so the order of the adds does not matter.
  std::vector<LiteMath::float4> points(n);
  std::vector<float> weights(cells, 0.0f), sums(3 * cells, 0.0f);
  for (int i = 0; i < n; ++i)
  {
    points[i] = LiteMath::float4(float(i % 5) * 0.125f, -float(i % 3) * 0.25f, float(i % 11), float(i % 4) * 0.5f);
    if (i % 97 == 0) points[i].w = i % 2 ? std::numeric_limits<float>::infinity() : std::nanf("");  // ReduceAdd skips these
    weights[i % cells] += 1.0f;  // the start (below)
    if (std::isfinite(points[i].w)) weights[i % cells] += points[i].w;
    for (int c = 0; c < 3; ++c) sums[3 * (i % cells) + c] += points[i][c];
  }
  REQUIRE(weights[1] > 10.0f);
  for (auto& [name, impl] : AllBackends(ctx, 8, 4))
  {
    INFO(name);
    impl->m_weights.assign(cells, 0.0f);
    for (int i = 0; i < n; ++i)
      impl->m_weights[i % cells] += 1.0f;  // a start the kernel adds to
    impl->CommitDeviceData();
    std::vector<float> out(3 * cells, 0.0f);
    impl->Splat(n, cells, points.data(), out.data());
    REQUIRE(impl->m_weights == weights);
    REQUIRE(out == sums);
  }
  RequireNoValidationMessages(ctx);
}
