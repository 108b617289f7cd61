// Cases about kernels' loops: statements before and after the loop nest (reductions set up, one-thread
// epilogues), loop bounds, members every thread sets alike.
#include "Conformance.h"

#include "LiteMath.h"

// A case compiles where this build translated its class (CONFORMANCE_CLASSES); main checks that all were.
#if __has_include("PointStats_CPU.h")
#include "PointStats_CPU.h"
#include "PointStats_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "PointStats_ISPC.h"
#endif
#endif
#if __has_include("FirstThread_CPU.h")
#include "FirstThread_CPU.h"
#include "FirstThread_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "FirstThread_ISPC.h"
#endif
#endif
#if __has_include("ElementTotals_CPU.h")
#include "ElementTotals_CPU.h"
#include "ElementTotals_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "ElementTotals_ISPC.h"
#endif
#endif
#if __has_include("HalfSum_CPU.h")
#include "HalfSum_CPU.h"
#include "HalfSum_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "HalfSum_ISPC.h"
#endif
#endif
#if __has_include("KeepPositive_CPU.h")
#include "KeepPositive_CPU.h"
#include "KeepPositive_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "KeepPositive_ISPC.h"
#endif
#endif
#if __has_include("ThresholdFlag_CPU.h")
#include "ThresholdFlag_CPU.h"
#include "ThresholdFlag_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "ThresholdFlag_ISPC.h"
#endif
#endif
#if __has_include("ArraySum_CPU.h")
#include "ArraySum_CPU.h"
#include "ArraySum_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "ArraySum_ISPC.h"
#endif
#endif
#if __has_include("LocalTotals_CPU.h")
#include "LocalTotals_CPU.h"
#include "LocalTotals_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "LocalTotals_ISPC.h"
#endif
#endif

#include <algorithm>
#include <stdexcept>

using namespace conformance;
using LiteMath::float4;

namespace {

std::vector<int> Ints(int n) {
  std::vector<int> v(n);
  for (int i = 0; i < n; i++) v[i] = (i * 7919) % 201 - 100;
  return v;
}

#if __has_include("PointStats_CPU.h")
Register pointStats(MakeCase<PointStats>(
    "statements before and after the loop nest: reductions set up, results written after", "point_stats.h/.cpp", 1e-5,
    CONFORMANCE_MAKERS(PointStats), [](PointStats& s) {
      const uint32_t n = 3000;
      std::vector<float4> points(n);
      for (uint32_t i = 0; i < n; i++) points[i] = float4(float(i % 97) - 40.0f, float((i * 31) % 89), -float(i % 13), 1.0f);
      std::vector<float4> summary(3, float4(-7.0f));
      s.m_sumX = 1234.0f;  // the kernel sets it up itself
      s.Compute(n, points.data(), summary.data());
      Outputs r;
      for (auto& p : summary) Append(r, std::vector<float>{p.x, p.y, p.z, p.w});
      Append(r, std::vector<float>{s.m_boxMin.x, s.m_boxMax.y, s.m_sumX});
      return r;
    }));
#endif

#if __has_include("HalfSum_CPU.h")
Register halfSum(MakeCase<HalfSum>(
    "a loop from n / 2 to <= n - 1 after the reduction is set up", "half_sum.h/.cpp", 0.0, CONFORMANCE_MAKERS(HalfSum), [](HalfSum& s) {
      std::vector<int> data = Ints(2049);
      s.m_summ = 99;
      s.Sum(data.data(), unsigned(data.size()));
      return Outputs{double(s.m_summ)};
    }));
#endif

#if __has_include("KeepPositive_CPU.h")
Register keepPositive(MakeCase<KeepPositive>(
    "an append kernel that empties its vector first and writes its size after", "keep_positive.h/.cpp", 0.0, CONFORMANCE_MAKERS(KeepPositive),
    [](KeepPositive& k) {
      const uint32_t n = 2000;
      std::vector<float> values(n);
      for (uint32_t i = 0; i < n; i++) values[i] = float((i * 13) % 17) - 8.0f;
      uint32_t count = 0;
      k.m_kept.push_back({7u, 7.0f});  // emptied by the kernel
      k.Filter(n, values.data(), &count);
      std::vector<Kept> kept = k.m_kept;
      std::sort(kept.begin(), kept.end(), [](const Kept& a, const Kept& b) { return a.index < b.index; });  // appends come in any order
      Outputs r{double(count), double(kept.size())};
      for (auto& x : kept) r.insert(r.end(), {double(x.index), double(x.value)});
      return r;
    }));
#endif

#if __has_include("ThresholdFlag_CPU.h")
Register thresholdFlag(MakeCase<ThresholdFlag>(
    "a member every thread may set to the same constant (m_flag = 1)", "threshold_flag.h/.cpp", 0.0, CONFORMANCE_MAKERS(ThresholdFlag),
    [](ThresholdFlag& t) {
      std::vector<float> values(500);
      for (int i = 0; i < 500; i++) values[i] = float(i % 50);
      Outputs r;
      t.Check(500, values.data(), 48.5f);
      r.push_back(t.m_flag);
      t.Check(500, values.data(), 60.0f);
      r.push_back(t.m_flag);
      r.push_back(7.0);  // a flag of 0 is a result too
      return r;
    }));
#endif

#if __has_include("ArraySum_CPU.h")
Register arraySum(MakeCase<ArraySum>(
    "size_t kernel parameters (32-bit on the GPU, with a note)", "array_sum.h/.cpp", 0.0, CONFORMANCE_MAKERS(ArraySum), [](ArraySum& a) {
      std::vector<int> data = Ints(5000);
      a.CalcArraySum(data.data(), unsigned(data.size()));
      return Outputs{double(a.m_sum)};
    }));
#endif

#if __has_include("LocalTotals_CPU.h")
Register localTotals(MakeCase<LocalTotals>(
    "locals reduced in the loop (sum += v, std::min/max, a float4, n++) and read after it", "local_totals.h/.cpp", 1e-5,
    CONFORMANCE_MAKERS(LocalTotals), [](LocalTotals& t) {
      t.CommitDeviceData();
      Outputs r;
      for (uint32_t n : {5000u, 1u, 0u}) {  // no threads at all: the locals keep their initial values
        std::vector<float4> values(std::max(n, 1u));
        for (uint32_t i = 0; i < n; i++) values[i] = float4(float(int(i * 37) % 101) - 30.0f, 0.5f, float(i % 7), -1.0f);
        std::vector<float> out(8, -7.0f);
        t.Summarize(n, values.data(), out.data());
        // Known answers, so that agreeing on nothing cannot pass.
        if (n == 0 && (out[0] != 0.0f || out[1] != 1e30f || out[3] != 1.0f || out[7] != 0.0f))
          throw std::runtime_error("with no values the locals should keep their initial values");
        if (n == 1 && (out[0] != -30.0f || out[1] != -30.0f || out[2] != -30.0f || out[6] != 3.0f || out[7] != 1.0f))
          throw std::runtime_error("one value: sum, min and max are that value");
        Append(r, out);
        r.push_back(t.m_mean);
        r.push_back(t.m_range);
      }
      return r;
    }));
#endif

#if __has_include("FirstThread_CPU.h")
Register firstThread(MakeCase<FirstThread>(
    "one thread writing elements at constant indices (if (i == 0) a_out[0] = v.x), a const local in a cast, a const array parameter",
    "first_thread.h/.cpp", 1e-6, CONFORMANCE_MAKERS(FirstThread), [](FirstThread& f) {
      std::vector<float> in = {0.75f, -1.5f, 2.0f, 0.125f, -0.5f, 1.25f, 3.0f, -2.25f, 0.0f, 0.5f, 1.0f, -1.0f};
      std::vector<float> out(in.size(), 10.0f);  // out[1] and out[3] are added to
      f.Run(int(in.size()), in.data(), out.data());
      Outputs r(out.begin(), out.end());
      r.insert(r.end(), f.m_firsts.begin(), f.m_firsts.end());
      return r;
    }));
#endif

#if __has_include("ElementTotals_CPU.h")
Register elementTotals(MakeCase<ElementTotals>(
    "elements of arrays reduced: members at constant indices (m_moments[3] += c * d.x), at a computed one (m_bins[bin] += 1), with std::min; locals; uint, int2, uint3, float4",
    "element_totals.h/.cpp", 1e-5, CONFORMANCE_MAKERS(ElementTotals), [](ElementTotals& t) {
      const int n = 1500;  // several workgroups and chunks
      std::vector<float4> samples(n);
      for (int i = 0; i < n; ++i)
        samples[i] = float4(std::sin(0.37f * float(i)), std::cos(0.11f * float(i)), float(i % 5) * 0.25f - 0.5f, float((i * 37) % 101) / 101.0f);
      for (int k = 0; k < ElementTotals::kMoments; ++k)
        t.m_moments[k] = float3(-9.0f);  // the kernel sets them up itself
      t.m_count = 77;
      t.Measure(n, samples.data());
      Outputs r;
      for (auto& m : t.m_moments) Append(r, std::vector<float>{m.x, m.y, m.z});
      Append(r, std::vector<float>(std::begin(t.m_bins), std::end(t.m_bins)));
      r.push_back(float(t.m_least[0]));
      r.push_back(float(t.m_least[1]));
      r.push_back(float(t.m_count));
      Append(r, std::vector<float>(std::begin(t.m_spread), std::end(t.m_spread)));
      Append(r, std::vector<float>(std::begin(t.m_highest), std::end(t.m_highest)));
      for (uint32_t v : t.m_top) r.push_back(float(v));
      for (auto& p : t.m_pairs) Append(r, std::vector<float>{float(p.x), float(p.y)});
      for (auto& c : t.m_counts) Append(r, std::vector<float>{float(c.x), float(c.y), float(c.z)});
      for (auto& l : t.m_low) Append(r, std::vector<float>{l.x, l.y, l.z, l.w});
      return r;
    }));
#endif

}  // namespace
