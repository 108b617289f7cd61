// A class that walks with its gang (Gang.h: CRT_UNIFORM, crossrt::AnyLane) gives every query the
// count it gives alone, on every backend: against the original class and against std::upper_bound,
// for queries in order (the gang's lanes agree for long) and shuffled (they part at once).
#include "gang_walk.h"
#include "KeyCounter_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "KeyCounter_ISPC.h"
#endif
#include "KeyCounter_Vulkan.h"
#include "TestSupport.h"

#include <algorithm>
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
      if (!ordered) std::shuffle(queries.begin(), queries.end(), rng);
      std::vector<uint32_t> expected(queries.size());
      uint32_t total = 0;
      for (size_t i = 0; i < queries.size(); ++i)
        total += expected[i] = uint32_t(std::upper_bound(keys.begin(), keys.end(), queries[i]) - keys.begin());
      REQUIRE(*std::min_element(expected.begin(), expected.end()) == 0u);  // queries below every key,
      REQUIRE(*std::max_element(expected.begin(), expected.end()) == keys.size());  // and above

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
        std::vector<uint32_t> counts(queries.size(), 0xFFFFFFFFu);
        impl->Count(int(queries.size()), queries.data(), counts.data());
        size_t wrong = 0;
        for (size_t i = 0; i < counts.size(); ++i) wrong += counts[i] != expected[i];
        REQUIRE(wrong == 0);
        REQUIRE(impl->m_total == total);
        REQUIRE(impl->m_mean == float(total) / float(queries.size()));
      }
    }
  }
  RequireNoValidationMessages(ctx);
}
