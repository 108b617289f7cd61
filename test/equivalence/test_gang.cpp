// A class that walks with its gang (Gang.h: CRT_UNIFORM, crossrt::AnyLane) gives every query the
// count it gives alone, on every backend: against the original class and against std::upper_bound,
// for queries in order (the gang's lanes agree for long) and shuffled (they part at once), with NaN
// queries that leave their gang early (crossrt::AllLanesOn() is false there); and the count of the
// quarters' first keys, which ISPC's whole gangs take a quad of lanes per query (LaneOfQuad, FromLane).
#include "gang_walk.h"
#include "KeyCounter_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "KeyCounter_ISPC.h"
#endif
#include "KeyCounter_Vulkan.h"
#include "TestSupport.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

TEST_CASE("A gang walking a sorted table together counts each query as the original does", "[equivalence][gang]")
{
  auto ctx = ValidatedContext();
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> value(0, 400);
  std::vector<float> keys(1003);  // 125 blocks of 8 and a tail of 3; values repeat
  for (float& k : keys) k = float(value(rng)) * 0.25f;
  std::sort(keys.begin(), keys.end());
  for (bool ordered : {true, false})
  {
    DYNAMIC_SECTION((ordered ? "queries in order" : "queries shuffled"))
    {
      std::vector<float> queries(4099);
      for (size_t i = 0; i < queries.size(); ++i) queries[i] = -2.0f + 104.0f * float(i) / float(queries.size());  // below, among, above the keys
      // NaN queries in some gangs: their lanes leave early, so those gangs take the branch that
      // crossrt::AllLanesOn() does not guard (on ISPC; every other gang and backend, the guarded one).
      for (size_t i = 3; i < queries.size() / 2; i += 97) queries[i] = std::numeric_limits<float>::quiet_NaN();
      if (!ordered) std::shuffle(queries.begin(), queries.end(), rng);
      std::vector<uint32_t> expected(queries.size());
      uint32_t total = 0;
      for (size_t i = 0; i < queries.size(); ++i)
      {
        expected[i] = std::isnan(queries[i]) ? KeyCounter::kNoCount : uint32_t(std::upper_bound(keys.begin(), keys.end(), queries[i]) - keys.begin());
        total += std::isnan(queries[i]) ? 0u : expected[i];
      }
      std::vector<uint32_t> expectedQuarters(queries.size());
      const float starts[4] = {keys[0], keys[keys.size() / 4], keys[2 * (keys.size() / 4)], keys[3 * (keys.size() / 4)]};
      for (size_t i = 0; i < queries.size(); ++i)
        expectedQuarters[i] = std::isnan(queries[i]) ? KeyCounter::kNoCount : uint32_t(std::count_if(starts, starts + 4, [&](float k) { return k <= queries[i]; }));
      for (uint32_t c = 0; c <= 4; ++c)  // every count, from below the first key to beyond the last quarter's
        REQUIRE(std::count(expectedQuarters.begin(), expectedQuarters.end(), c) > 0);
      REQUIRE(*std::min_element(expected.begin(), expected.end()) == 0u);  // queries below every key,
      REQUIRE(std::count(expected.begin(), expected.end(), uint32_t(keys.size())) > 0);  // and above

      std::vector<std::pair<const char*, std::shared_ptr<KeyCounter>>> impls = {{"original", std::make_shared<KeyCounter>(keys)},
                                                                                {"CPU", CreateKeyCounter_CPU(keys)}};
#ifdef CROSSRT_HAS_ISPC
      impls.push_back({"ISPC", CreateKeyCounter_ISPC(keys)});
#endif
      if (ctx) impls.push_back({"Vulkan", CreateKeyCounter_Vulkan(ctx, keys)});
      for (auto& [name, impl] : impls)
      {
        INFO(name);
        impl->CommitDeviceData();
        std::vector<uint32_t> counts(queries.size(), 0xEEEEEEEEu);  // neither a count nor kNoCount
        impl->Count(int(queries.size()), queries.data(), counts.data());
        size_t wrong = 0;
        for (size_t i = 0; i < counts.size(); ++i) wrong += counts[i] != expected[i];
        REQUIRE(wrong == 0);
        REQUIRE(impl->m_total == total);
        REQUIRE(impl->m_mean == float(total) / float(queries.size()));
        // The quarters' first keys, a quad of lanes per query on ISPC where a gang is whole.
        std::vector<uint32_t> quarters(queries.size(), 0xEEEEEEEEu);
        impl->CountQuarters(int(queries.size()), queries.data(), quarters.data());
        wrong = 0;
        for (size_t i = 0; i < quarters.size(); ++i)
          wrong += quarters[i] != expectedQuarters[i];
        REQUIRE(wrong == 0);
      }
    }
  }
  RequireNoValidationMessages(ctx);
}
