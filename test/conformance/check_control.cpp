// Host code between kernel calls, run as the CPU runs it (issue 52): a solver that reads the
// residual its kernel reduced and stops early, swaps of member vectors, and member vectors handed
// to kernels through data(). Each run also checks a known answer, so that backends agreeing on
// garbage cannot pass.
#include "Conformance.h"

#include <stdexcept>
#include <string>

#if __has_include("HeatDiffusion_CPU.h")
#include "HeatDiffusion_CPU.h"
#include "HeatDiffusion_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "HeatDiffusion_ISPC.h"
#endif
#endif
#if __has_include("KMeans_CPU.h")
#include "KMeans_CPU.h"
#include "KMeans_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "KMeans_ISPC.h"
#endif
#endif
#if __has_include("Ledger_CPU.h")
#include "Ledger_CPU.h"
#include "Ledger_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Ledger_ISPC.h"
#endif
#endif
#if __has_include("PingPong_CPU.h")
#include "PingPong_CPU.h"
#include "PingPong_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "PingPong_ISPC.h"
#endif
#endif

using namespace conformance;

namespace {

#if __has_include("HeatDiffusion_CPU.h")
// Solve: steps until converged, the residual read between kernel calls; then again, checking
// every 7th step only (it stops at a multiple of 7, no earlier than the first).
Register heatDiffusion(MakeCase<HeatDiffusion>(
    "iterate until converged: a reduced residual read between kernel calls, std::swap and .swap() of member vectors, an early break/return",
    "solver_loops.h/.cpp", 1e-5, CONFORMANCE_MAKERS(HeatDiffusion, 24, 16), [](HeatDiffusion& d) {
      d.CommitDeviceData();
      Outputs r;
      d.Solve(5000, 0.01f);
      const int first = d.Steps();
      if (first <= 1 || first >= 5000 || d.Residual() >= 0.01f)
        throw std::runtime_error("Solve should stop early, below the tolerance (" + std::to_string(first) + " steps, residual " +
                                 std::to_string(d.Residual()) + ")");
      r.push_back(first);
      r.push_back(d.Residual());
      Append(r, d.Temperature());
      d.SolveChecked(5000, 0.001f, 7);
      if (d.Steps() % 7 != 0 || d.Steps() >= 5000 || d.Temperature()[0] != 100.0f)
        throw std::runtime_error("SolveChecked should stop at a multiple of 7 steps with the edge at 100 (" + std::to_string(d.Steps()) + " steps)");
      r.push_back(d.Steps());
      r.push_back(d.Residual());
      Append(r, d.Temperature());
      return r;
    }));
#endif

#if __has_include("PingPong_CPU.h")
Register pingPong(MakeCase<PingPong>(
    "std::swap of member vectors between kernel calls and after the last one; a member's data() to a kernel that writes it", "solver_loops.h/.cpp", 0.0,
    CONFORMANCE_MAKERS(PingPong, 100), [](PingPong& p) {
      p.CommitDeviceData();
      Outputs r;
      p.Run(3);
      if (p.m_a[0] != 3 || p.m_a[99] != 3 || p.m_b[0] != 2)
        throw std::runtime_error("after Run(3) m_a should be 3 and m_b 2, not " + std::to_string(p.m_a[0]) + " and " + std::to_string(p.m_b[0]));
      Append(r, p.m_a);
      Append(r, p.m_b);
      p.Fill(7);
      if (p.m_a[0] != 7 || p.m_a[50] != 7) throw std::runtime_error("after Fill(7) m_a should be 7, not " + std::to_string(p.m_a[0]));
      p.Run(2);
      if (p.m_a[0] != 9) throw std::runtime_error("after Fill(7) and Run(2) m_a should be 9, not " + std::to_string(p.m_a[0]));
      p.Twice();
      if (p.m_b[0] != 18 || p.m_first != 27) throw std::runtime_error("Twice should give m_b = 18 and m_first = 27, not " + std::to_string(p.m_b[0]) +
                                                                       " and " + std::to_string(p.m_first));
      Append(r, p.m_a);
      Append(r, p.m_b);
      r.push_back(p.m_first);
      // A swap after the last kernel swaps the device buffers too: the next call sees them swapped.
      p.FillAndSwap(4);
      p.Run(1);
      if (p.m_a[0] != 19 || p.m_b[0] != 18)
        throw std::runtime_error("after FillAndSwap(4) and Run(1) m_a should be 19 and m_b 18, not " + std::to_string(p.m_a[0]) + " and " +
                                 std::to_string(p.m_b[0]));
      Append(r, p.m_a);
      Append(r, p.m_b);
      // A change after the last kernel reaches the device copy the next call uses.
      p.FillThenSet(5);
      p.Run(1);
      if (p.m_a[0] != -4 || p.m_a[1] != 6)
        throw std::runtime_error("after FillThenSet(5) and Run(1) m_a should start -4, 6, not " + std::to_string(p.m_a[0]) + ", " + std::to_string(p.m_a[1]));
      Append(r, p.m_a);
      return r;
    }));
#endif

#if __has_include("KMeans_CPU.h")
// Fit: the host clears the counts, moves the centroids to the means and reads the number of
// changed labels between kernel calls. Integer points: the sums are exact in any order, so every
// backend must give the same centroids, labels and number of rounds.
Register kMeans(MakeCase<KMeans>(
    "k-means: member vectors read (counts, sums) and written (counts, centroids) on the host between kernel calls, an early break",
    "clustering.h/.cpp", 1e-5, CONFORMANCE_MAKERS(KMeans, 600, 4), [](KMeans& k) {
      k.CommitDeviceData();
      Outputs r;
      k.Fit(50);
      int total = 0;
      for (int c : k.Counts()) total += c;
      // The four blobs are found: each cluster holds a quarter of the points, its centroid near a blob's centre.
      if (k.Iterations() <= 2 || k.Iterations() >= 50 || total != 600 || k.Counts()[0] != 150 || k.Counts()[3] != 150)
        throw std::runtime_error("Fit should find the four blobs of 150 points in a few rounds (" + std::to_string(k.Iterations()) + " rounds, counts " +
                                 std::to_string(k.Counts()[0]) + " " + std::to_string(k.Counts()[1]) + " " + std::to_string(k.Counts()[2]) + " " +
                                 std::to_string(k.Counts()[3]) + ")");
      r.push_back(k.Iterations());
      for (const float2& c : k.Centroids()) r.push_back(c.x), r.push_back(c.y);
      Append(r, k.Labels());
      Append(r, k.Counts());
      return r;
    }));
#endif

#if __has_include("Ledger_CPU.h")
// User names equal to the generated code's own: each keeps meaning the user's. Integer-valued
// floats, so the GPU's sum is exact. Run twice: the second sees m_pipelines[0] the first set.
Register ledger(MakeCase<Ledger>(
    "user names equal to the generated code's (m_vdata, m_ctx, m_pipelines, a_cmd, Synchronize, threadId, inRange, ...)",
    "names_in_use.h/.cpp", 0.0, CONFORMANCE_MAKERS(Ledger, 64), [](Ledger& l) {
      l.CommitDeviceData();
      Outputs r;
      for (int round = 0; round < 2; ++round)
      {
        l.Run(100 + round, 2.0f);
        Append(r, l.m_images);
        Append(r, l.m_pipelines);
        for (double v : {double(l.m_times), double(l.m_args), double(l.m_recording), double(l.m_hostTail_Run), double(l.m_ctx), double(l.m_scenes)})
          r.push_back(v);
      }
      if (l.m_recording != 101 + 90 || l.m_hostTail_Run != 106 || l.m_args != 5 + int(l.m_times) || l.m_pipelines[0] != l.m_times || l.m_times == 0.0f)
        throw std::runtime_error("Ledger's members should hold what Run computed (m_recording " + std::to_string(l.m_recording) + ", m_args " +
                                 std::to_string(l.m_args) + ", m_times " + std::to_string(l.m_times) + ")");
      return r;
    }));
#endif

}  // namespace
