// The CPU backend's versions of library calls in control functions, and of push_back in kernels,
// the choice of each kernel's loop between all cores and one, and an _ISPC kernel's between SIMD
// lanes and its scalar loop (header only; OpenMP).
#pragma once
#include "CpuLoops.h"
#include "LaneMemory.h"
#include "SortKey.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>
#include <vector>

namespace crossrt {

// Two ways of running one loop, way 1 the one it is written for and way 0 the other, each with
// its mean time per iteration as measured (an exponential moving average, outliers and all). The
// slower way is tried again now and then, after 16 calls, then 64, 256, up to 1024 while it keeps
// losing (its mean starts afresh from that run), so that the choice follows the machine. The
// choices below decide when each way runs; this keeps their times.
class MeasuredWays {
 public:
  // Calls between tries of the slower way: the first wait, 4x longer after each try it lost, up to
  // the longest.
  static constexpr unsigned kFirstWait = 16, kLongestWait = 1024;
  // A remembered mean of the slower way within this factor of the verdict's (its new mean, or the
  // one remembered beside it) is tried at once (Record).
  static constexpr float kCloseToVerdict = 1.25f;

  // The mean ms per iteration measured for a way (-1 before the first), for tests and benchmarks.
  float Mean(int way) const { return m_msPerIteration[way ? 1 : 0].load(std::memory_order_relaxed); }

  // The next run is a try of the way that is not the faster one (or has not run yet).
  void Try() { m_tryingOther.store(true, std::memory_order_relaxed); }
  // Whether the run now under way is such a try (between the choice and its Record).
  bool Trying() const { return m_tryingOther.load(std::memory_order_relaxed); }

  // The ways' means as earlier runs left them (LaneMemory; -1 for a way none measured): where both
  // have one, the faster is the verdict and the other is tried after kFirstWait calls, or at once
  // where the verdict alone has run in the last kFirstWait - 1 runs (a program that calls the loop
  // once a run). A way's first run here replaces its remembered mean.
  void Seed(float way1Ms, float way0Ms, int verdictOnlyRuns) {
    const float ms[2] = {way0Ms, way1Ms};
    for (int w = 0; w < 2; ++w) {
      m_msPerIteration[w].store(ms[w] > 0.0f ? ms[w] : -1.0f, std::memory_order_relaxed);
      m_remembered[w].store(ms[w] > 0.0f, std::memory_order_relaxed);
    }
    if (way1Ms > 0.0f && way0Ms > 0.0f) {
      m_verdict.store(way1Ms <= way0Ms ? 1 : 0, std::memory_order_relaxed);
      if (verdictOnlyRuns + 1 >= int(kFirstWait)) m_calls.store(m_nextTry.load(std::memory_order_relaxed), std::memory_order_relaxed);
    }
  }

  // Whether a way's mean is still the one an earlier run left (Seed): none of its runs here counted.
  bool MeanRemembered(int way) const { return m_remembered[way ? 1 : 0].load(std::memory_order_relaxed); }

  // The time of a try of `way` that beat the other's mean once and waits for its second (Record),
  // or -1. At the program's end it is that way's latest time, and what the next run should start
  // from: the mean it would replace may be an earlier run's.
  float PendingTry(int way) const {
    return m_firstTryWay.load(std::memory_order_relaxed) == (way ? 1 : 0) ? m_firstTry.load(std::memory_order_relaxed) : -1.0f;
  }

  // Counts a call that keeps to the faster way; true when the slower one is due for a try.
  bool TimeToTry() {
    if (m_calls.fetch_add(1, std::memory_order_relaxed) + 1 < m_nextTry.load(std::memory_order_relaxed)) return false;
    m_calls.store(0, std::memory_order_relaxed);
    Try();
    return true;
  }

  // The way that has been faster (1 or 0), or -1 before both have run. It changes only on a try of
  // the other way: where the work changes (another mesh, 10x the size) the verdict's mean follows it
  // while the other's stays what it measured long ago, and comparing the two would switch on a stale
  // number. (bench_lbvh's PrimaryRays_ISPC so ran its scalar loop, at 0.72-0.84x of Embree against
  // 0.95-1.03x in lanes, on the largest mesh, sse4 on an AMD EPYC, Zen 4: its lanes' mean had grown
  // past the scalar loop's, measured on a smaller mesh.) So where the verdict's mean passes the other's, the next call tries the other.
  int Verdict() const { return m_verdict.load(std::memory_order_relaxed); }

  // A try that beats the verdict's mean is not believed at once either: one noisy call (a thread
  // taken off its core, a page fault) would switch the kernel to the slower way until the next try.
  // The next call tries it again, and the mean of both tries decides.
  void Record(int way, float msPerIteration) {
    const int w = way ? 1 : 0;
    const bool tried = m_tryingOther.exchange(false, std::memory_order_relaxed);
    const float before = Mean(w), other = Mean(1 - w);
    const float firstTry = m_firstTry.load(std::memory_order_relaxed);
    if (tried && firstTry < 0.0f && other >= 0.0f && msPerIteration < other) {
      m_firstTry.store(msPerIteration, std::memory_order_relaxed);  // faster once: tried again on the next call
      m_firstTryWay.store(w, std::memory_order_relaxed);
      m_calls.store(m_nextTry.load(std::memory_order_relaxed), std::memory_order_relaxed);
      return;
    }
    if (tried && firstTry >= 0.0f) {  // the second try: the mean of both
      msPerIteration = 0.5f * (firstTry + msPerIteration);
      m_firstTry.store(-1.0f, std::memory_order_relaxed);
      m_firstTryWay.store(-1, std::memory_order_relaxed);
      m_calls.store(0, std::memory_order_relaxed);
    }
    // A way tried again after a while starts its mean afresh: what it measured then is stale; so does
    // a way's first run after a mean remembered from an earlier run (Seed).
    const bool remembered = m_remembered[w].exchange(false, std::memory_order_relaxed);
    const bool fresh = before < 0.0f || tried || remembered;
    m_msPerIteration[w].store(fresh ? msPerIteration : before + 0.3f * (msPerIteration - before), std::memory_order_relaxed);
    if (Mean(0) < 0.0f || Mean(1) < 0.0f) return;
    const int faster = Mean(1) <= Mean(0) ? 1 : 0;
    if (tried || Verdict() < 0) {
      m_verdict.store(faster, std::memory_order_relaxed);
      if (tried) {  // when the way tried still loses, the next try waits four times as long
        const unsigned wait = m_nextTry.load(std::memory_order_relaxed);
        m_nextTry.store(faster == w ? kFirstWait : std::min(wait * 4u, kLongestWait), std::memory_order_relaxed);
      }
    } else if (faster != Verdict() || (MeanRemembered(1 - Verdict()) && Mean(1 - Verdict()) <= kCloseToVerdict * Mean(Verdict())) ||
               (w == Verdict() && remembered && MeanRemembered(1 - w) && Mean(1 - w) <= kCloseToVerdict * before)) {
      // The other way, measured again next: it is faster by the means, or its mean is an earlier run's
      // and close to the verdict's (within kCloseToVerdict), too close to trust across runs that may
      // have traced another mesh or run another build of the kernel, and a try of it costs a fraction
      // of one call. (bench_lbvh's PrimaryRays_ISPC, sse4 on an AMD EPYC, Zen 5: the lanes' mean that
      // another build had left, 0.060 ms per 1,000 rays, kept the 871k-triangle dragon on the scalar
      // loop at 0.054-0.060 for 15 calls in a row; the lanes, tried at last, took 0.044.)
      // The same where the two were that close in the earlier run (the verdict's first mean here being
      // its first counted run after Seed): where this run's work is lighter or heavier (another mesh),
      // both ways' times move, and the other's old mean against the verdict's new one says nothing.
      // (The same bench, 2026-12-02: the lanes remembered at 0.092 ms per 1,000 rays beside the scalar
      // loop at 0.084, which took 0.041 here; tried on the 16th call, the lanes took 0.029.) Where the
      // two were far apart, no such try: a first version tried the other way wherever the verdict's
      // time moved by more than a quarter, noise on a kernel of microseconds, and on the 992-triangle
      // teapot LBVH_ISPC's Refit so tried its lanes at 0.079 ms against its scalar loop's 0.013.
      m_calls.store(m_nextTry.load(std::memory_order_relaxed), std::memory_order_relaxed);
    }
  }

 private:
  std::atomic<float> m_msPerIteration[2] = {-1.0f, -1.0f};
  std::atomic<unsigned> m_calls{0};
  std::atomic<unsigned> m_nextTry{kFirstWait};
  std::atomic<bool> m_tryingOther{false};
  std::atomic<float> m_firstTry{-1.0f};  // a try that won once, waiting for its second
  std::atomic<int> m_firstTryWay{-1};    // the way of that try
  std::atomic<int> m_verdict{-1};
  std::atomic<bool> m_remembered[2] = {false, false};  // the way's mean is an earlier run's (Seed)
};

// Iterations of a loop in classes 4x apart: [4^c, 4^(c+1)), the last open-ended. A loop's ways are
// measured per class (ParallelChoice, LaneChoice): what is small may run best one way and what is
// large the other, and a time per iteration measured on small loops, where starting the threads
// dominates, says nothing of a large one.
constexpr int kLoopSizeClasses = 16;
inline int LoopSizeClass(long long iterations) {
  int c = 0;
  for (long long n = iterations; n >= 4 && c + 1 < kLoopSizeClasses; n /= 4) ++c;
  return c;
}

// Whether a kernel's loop runs on all cores this call, or on the calling thread alone: each
// generated _CPU and _ISPC kernel keeps one (a static of its method) and asks it before the loop,
//   static crossrt::ParallelChoice crt_choice;
//   const auto crt_loop = crt_choice.Begin(count);
//   crossrt::ParallelFor<int>(crt_loop.parallel, 0, count, grain, [&](int crt_first, int crt_last) { ... });
//   crt_choice.End(crt_loop);
//
// Why: a parallel loop ends when its slowest thread does. On a machine where other programs keep
// cores busy, the scheduler takes a worker off its core for a time slice (milliseconds) now and
// then, and the loop waits for it. A loop of a few hundred microseconds then takes ten or a
// hundred times that (ParallelFor no longer waits for a worker that never started, but still for
// one taken off its core in the middle of a chunk): beside one busy thread on 2 cores (AMD EPYC, bench_lbvh --load 1), the
// LBVH_CPU build of an 11,102-triangle mesh (eight kernel calls) took 4.3-4.8 ms, and 54 ms in some
// runs, against 1.0 ms quiet and 1.9 ms for the single-threaded original. Passive waits alone
// (OMP_WAIT_POLICY) collapsed the same way; beside this choice they help (runtime/src/OpenMPWaits.cpp).
//
// So each loop runs the way that has been faster here, as measured (MeasuredWays: all cores are
// way 1, one core way 0), per size class of its iterations (LoopSizeClass). A try of one core costs
// the loop's work, so it is made only where one core can win (MayTryOneCore): where what the other
// threads save, the work on one core times (threads - 1) / threads, is under a time slice
// (kSliceMs), since a parallel run waits up to a time slice for a descheduled thread. The work is a
// measured time on one core per iteration (of this size class, or the nearest class that has one:
// it hardly depends on the loop's length) times the iterations. Before a loop has run on one core,
// its fastest parallel run, times the other threads, stands in for it; that overstates it under
// load, so while other threads are runnable (Loaded: the kernel's procs_running beyond this thread)
// a parallel run of under kLoadedTryMs gets the first try too. On a 16-core Intel Xeon with 16 busy
// threads the first parallel runs of the LBVH build's kernels took about 8 ms each, and without a
// try the build of 11,102 triangles took 116 ms against the original's 1.7 (1.3 ms with it).
// A long loop always runs on all cores (with one core busy, Bloom_CPU's 25-tap blur measured 1.18x
// and 1.53x of the original when its loops could be tried on one core once slowed, 1.69x and 1.60x
// on all cores). Loops inside a parallel region run on their thread, as OpenMP would.
//
// procs_running decides nothing more: it also counts threads that yield their cores at once (TBB's
// workers spinning after an Embree build, most likely), and with tries of up to 40 ms of work
// whenever it was over 0, a quiet 16-core Xeon built 52k-202k triangles in 3x OpenMP's time.
//
// Why size classes: measured together, a kernel called first on a 992-triangle mesh (where one core
// wins, starting 16 threads costing more than the loop) kept that verdict for its loops over 871k
// triangles, where all cores were many times faster, and ran them on one core until its next try
// (LBVH_ISPC built that mesh in 2.8x LBVH_CPU's time on a 16-core Intel Xeon).
// CROSSRT_CPU_PARALLEL=always turns the choice off: every loop runs on all cores.
//
// Both ways compute the same loop: the _ISPC classes fold their chunks in order, so their results
// do not change with the number of threads; the _CPU classes' reductions already differ in their
// last bits from run to run (the dynamic schedule hands out iterations in any order).
class ParallelChoice {
 public:
  // A time slice of a loaded Linux scheduler (CFS gives 3-4 ms each to two runnable threads on a
  // core): what a parallel loop waits for a descheduled thread.
  static constexpr double kSliceMs = 4.0;
  // While other threads are runnable, a loop whose fastest parallel run took under this gets its
  // first try on one core.
  static constexpr double kLoadedTryMs = 10 * kSliceMs;

  struct Run {
    bool parallel;
    long long iterations;
    std::chrono::steady_clock::time_point start;
    bool counted = true;  // false: a run this choice did not choose (an _ISPC way's try), not in its means
  };

  Run Begin(long long iterations) { return {Choose(iterations), iterations, std::chrono::steady_clock::now()}; }

  // The same for a way of an _ISPC kernel (its LaneChoice::Run, defined below): while LaneChoice
  // tries the way that is not its verdict, the try runs on as many cores as the verdict's last run
  // of loops of that size did, so that the two ways are timed alike. (Beside two busy threads, a
  // try on all cores of a way whose verdict ran on one core waited a time slice for a worker taken
  // off its core, and a lanes' way lost for that.) The way learns which it ran on.
  // (CROSSRT_CPU_PARALLEL=always still puts every loop on all cores.)
  //
  // Each of the two choices counts only the runs where the other took its verdict: a lanes' try is
  // not in this choice's means, and the way learns when this choice tries the cores that are not its
  // verdict (coresTried), which LaneChoice then leaves out of its own. Before, a kernel's second call
  // (this choice's try of one core) put one core's time into the lanes' mean and made it the cores
  // the scalar loop's try followed: LBVH_ISPC's kernel1D_MakeLeaves so measured its scalar loop once
  // on one core, at 10.3 ms against the lanes' 3.2 on all cores, and ran in lanes, which take 3.2 ms
  // to the scalar loop's 2.4 on all cores (avx2, AMD EPYC, Zen 5, 2 threads; bench_lbvh, dragon res2).
  template <typename Way>
  Run Begin(long long iterations, Way& way) {
    const bool followVerdict = way.trying && way.verdictCores >= 0 && !AlwaysAllCores() && !OneThreadOnly(iterations);
    const bool parallel = followVerdict ? way.verdictCores == 1 : Choose(iterations);
    way.cores = parallel ? 1 : 0;
    way.coresTried = !followVerdict && !OneThreadOnly(iterations) && m_bySize[LoopSizeClass(iterations)].Trying();
    return {parallel, iterations, std::chrono::steady_clock::now(), !followVerdict};
  }

  void End(const Run& run) {
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - run.start).count();
    if (run.counted) Record(run.parallel, run.iterations, ms);
  }

  // The decision and the measurement apart, for tests.
  bool Choose(long long iterations) {
    const int threads = omp_get_max_threads();
    if (OneThreadOnly(iterations)) return false;
    if (AlwaysAllCores()) return true;
    Ways& ways = m_bySize[LoopSizeClass(iterations)];
    const float serial = ways.Mean(0), parallel = ways.Mean(1);
    if (parallel < 0.0f) return true;  // first, the way the loop is written for
    const double work = Work(iterations);
    if (serial >= 0.0f && ways.Verdict() == 0) {
      // One core has been faster: all cores now and then. But a long loop runs on all cores even
      // so (its parallel runs under load vary by time slices; with the choice's first try under
      // load and no such rule, Bloom_CPU beside one busy thread fell to 0.84-1.26x of the original).
      if (work >= 0.0 && !MayTryOneCore(iterations, threads, work)) return true;  // (no procs_running read here)
      return ways.TimeToTry();
    }
    if (!MayTryOneCore(iterations, threads, work)) return true;
    if (serial < 0.0f) {  // one core, once, to compare
      ways.Try();
      return false;
    }
    return !ways.TimeToTry();
  }

  void Record(bool parallel, long long iterations, double ms) {
    if (OneThreadOnly(iterations)) return;
    Ways& ways = m_bySize[LoopSizeClass(iterations)];
    const float now = float(ms / double(iterations));
    ways.Record(parallel, now);
    if (parallel && now < ways.fastestParallel.load(std::memory_order_relaxed)) ways.fastestParallel.store(now, std::memory_order_relaxed);
  }

  // The mean ms per iteration of a way (all cores: true) for loops of this many iterations (-1
  // before the first), for tests and benchmarks.
  float Mean(bool parallel, long long iterations) const { return m_bySize[LoopSizeClass(iterations)].Mean(parallel); }

  // Tests: take `others` threads as runnable beside this one, instead of reading /proc/stat.
  void AssumeOthersRunnable(int others) { m_othersForTests = others; }

  // CROSSRT_CPU_PARALLEL=always: every loop on all cores, as OpenMP alone would (to compare).
  static bool AlwaysAllCores() {
    static const bool always = [] {
      const char* v = std::getenv("CROSSRT_CPU_PARALLEL");
      return v != nullptr && std::strcmp(v, "always") == 0;
    }();
    return always;
  }

  // Threads that the kernel counts as runnable beside the calling one (procs_running in /proc/stat,
  // read at most every 20 ms; 0 where it cannot be read).
  static int OthersRunnable() {
    using Clock = std::chrono::steady_clock;
    static std::atomic<long long> readAt{-1000000000};
    static std::atomic<int> others{0};
    const long long now = std::chrono::duration_cast<std::chrono::microseconds>(Clock::now().time_since_epoch()).count();
    if (now - readAt.load(std::memory_order_relaxed) < 20000) return others.load(std::memory_order_relaxed);
    readAt.store(now, std::memory_order_relaxed);
    int running = 1;
    if (std::FILE* f = std::fopen("/proc/stat", "r")) {
      char line[256];
      while (std::fgets(line, sizeof line, f))
        if (std::sscanf(line, "procs_running %d", &running) == 1) break;
      std::fclose(f);
    }
    others.store(std::max(0, running - 1), std::memory_order_relaxed);
    return std::max(0, running - 1);
  }

 private:
  struct Ways : MeasuredWays {
    std::atomic<float> fastestParallel{3.0e38f};
  };

  // A loop that can only run on this thread: one iteration, inside a parallel loop, or one thread in all.
  static bool OneThreadOnly(long long iterations) { return iterations < 2 || InParallelLoop() || omp_get_max_threads() < 2; }

  bool Loaded() const { return (m_othersForTests >= 0 ? m_othersForTests : OthersRunnable()) > 0; }

  // The loop's work in ms on one core: its time per iteration there (in its size class, else the
  // nearest class that has one: it hardly depends on the loop's length) times the iterations; -1
  // before any run on one core.
  double Work(long long iterations) const {
    const int size = LoopSizeClass(iterations);
    for (int d = 0; d < kLoopSizeClasses; ++d)
      for (int c : {size - d, size + d})
        if (c >= 0 && c < kLoopSizeClasses && m_bySize[c].Mean(0) >= 0.0f) return double(m_bySize[c].Mean(0)) * double(iterations);
    return -1.0;
  }

  // Whether a try of one core may pay, and costs little (see above).
  bool MayTryOneCore(long long iterations, int threads, double work) const {
    if (work >= 0.0) return work * double(threads - 1) / double(threads) < kSliceMs;
    const double fastestMs = double(m_bySize[LoopSizeClass(iterations)].fastestParallel.load(std::memory_order_relaxed)) * double(iterations);
    return fastestMs * double(threads - 1) < kSliceMs || (fastestMs < kLoadedTryMs && Loaded());
  }

  Ways m_bySize[kLoopSizeClasses];
  int m_othersForTests = -1;
};

// Stable LSD radix sort of n records of key.strideWords words, on all cores or one (see below):
// per pass of 11 bits (three passes cover a 32-bit key), the digits of each slice of the records
// (one slice per thread) are counted, the counts scanned in (digit, slice) order, and each slice's
// records moved to their places. A pass whose digit is the same in every record moves nothing and is skipped
// (keys below 2^22 take two passes).
inline void RadixSortWords(uint32_t* records, size_t n, const SortKey& key) {
  constexpr uint32_t kDigitBits = 11, kDigits = 1u << kDigitBits;
  const size_t stride = key.strideWords;
  // The scratch copy is kept for the next sort of this thread: a fresh one would be zeroed (and
  // its pages faulted in) on every call, only for the sort to overwrite it.
  static thread_local std::vector<uint32_t> scratch;
  if (scratch.size() < n * stride) scratch.resize(n * stride);
  // Below 4,096 records the passes' 2,048 digits cost more than the records: a comparison sort of
  // (key, place) pairs, in the same stable order, then the records moved to their places. (992
  // records of two words: 9 us, against the passes' 20 and std::sort's 7, on an AMD EPYC, Zen 4;
  // with the passes, the LBVH_CPU build of the 992-triangle teapot took 1.07-1.17x the time of the
  // original, which sorts with std::sort.)
  if (n < 4096) {
    static thread_local std::vector<uint64_t> order;
    order.resize(n);
    for (size_t i = 0; i < n; ++i) order[i] = (uint64_t(SortableBits(records[i * stride + key.keyWord], key)) << 32) | i;
    std::sort(order.begin(), order.end());
    for (size_t i = 0; i < n; ++i) {  // (word by word: a copy call per record cost more than the sort)
      const uint32_t* from = records + (order[i] & 0xffffffffu) * stride;
      for (size_t w = 0; w < stride; ++w) scratch[i * stride + w] = from[w];
    }
    std::copy(scratch.data(), scratch.data() + n * stride, records);
    return;
  }
  uint32_t* src = records;
  uint32_t* dst = scratch.data();
  // Below 2^15 records, waking the other threads costs more than they save: with this, the LBVH
  // build of the 992-triangle teapot went from 1.1x to 0.8x of Embree LOW's time. Above, the sort
  // runs on all cores or one as a kernel's loop does (ParallelChoice). When its passes met at
  // OpenMP barriers, beside one busy thread on 2 cores the LBVH build of 47,794 triangles took 53 ms
  // in some runs, against 2-4 ms in others; on the pool, the OpenMP threads no longer take turns
  // with the pool's on the cores either.
  static ParallelChoice choice;
  const bool large = n >= (size_t(1) << 15);
  const ParallelChoice::Run run = choice.Begin(large ? static_cast<long long>(n) : 1);
  // The records in slices, one per thread, each counted and moved in order by whichever thread
  // takes it (ParallelFor, as the kernels' loops: no barrier waits for a thread that never started).
  const bool parallel = large && run.parallel;
  const int slices = parallel ? LoopThreads() : 1;
  std::vector<size_t> counts(size_t(slices) * kDigits);
  auto slice = [&](int s, size_t& begin, size_t& end) {
    begin = n * size_t(s) / size_t(slices);
    end = n * size_t(s + 1) / size_t(slices);
  };
  for (uint32_t shift = 0; shift < 32; shift += kDigitBits) {
    std::fill(counts.begin(), counts.end(), 0);
    ParallelFor<int>(parallel, 0, slices, 1, [&](int first, int last) {
      for (int s = first; s < last; ++s) {
        size_t begin, end;
        slice(s, begin, end);
        size_t* mine = &counts[size_t(s) * kDigits];
        for (size_t i = begin; i < end; ++i) ++mine[(SortableBits(src[i * stride + key.keyWord], key) >> shift) & (kDigits - 1)];
      }
    });
    // Each (digit, slice)'s first place, in that order: the sort is stable.
    bool oneDigit = false;
    size_t position = 0;
    for (uint32_t digit = 0; digit < kDigits; ++digit) {
      size_t inDigit = 0;
      for (int s = 0; s < slices; ++s) {
        const size_t c = counts[size_t(s) * kDigits + digit];
        counts[size_t(s) * kDigits + digit] = position;
        position += c;
        inDigit += c;
      }
      oneDigit = oneDigit || inDigit == n;
    }
    if (oneDigit) continue;
    ParallelFor<int>(parallel, 0, slices, 1, [&](int first, int last) {
      for (int s = first; s < last; ++s) {
        size_t begin, end;
        slice(s, begin, end);
        size_t* mine = &counts[size_t(s) * kDigits];
        for (size_t i = begin; i < end; ++i) {
          const uint32_t digit = (SortableBits(src[i * stride + key.keyWord], key) >> shift) & (kDigits - 1);
          const size_t to = mine[digit]++;
          if (stride == 1)  // the common shapes, without a call to memcpy per record
            dst[to] = src[i];
          else if (stride == 2)
            std::memcpy(dst + 2 * to, src + 2 * i, 8);
          else
            std::memcpy(dst + to * stride, src + i * stride, stride * sizeof(uint32_t));
        }
      }
    });
    std::swap(src, dst);
  }
  if (src != records) {  // an odd number of passes moved records: the result is in scratch
    const long long words = static_cast<long long>(n * stride);
    ParallelFor<long long>(parallel, 0, words, 1 << 16, [&](long long first, long long last) { std::copy(src + first, src + last, records + first); });
  }
  choice.End(run);
}

// std::sort of a range the translator recognized (see SortKey), on all cores.
template <typename Iterator>
void RadixSort(Iterator first, Iterator last, const SortKey& key) {
  const auto n = last - first;
  if (n <= 1) return;
  static_assert(sizeof(*first) % 4 == 0, "records of whole 32-bit words");
  RadixSortWords(reinterpret_cast<uint32_t*>(&*first), size_t(n), key);
}

// Whether an _ISPC class's kernel runs its loop nest in SIMD lanes (the ISPC function) this call,
// or as the _CPU class runs it, one iteration at a time per core: each kernel of an _ISPC class
// keeps one and asks it first,
//   static crossrt::LaneChoice crt_lanes;
//   crossrt::LaneChoice::Run crt_way = crt_lanes.Begin();
//   if (crt_way.lanes) crt_<kernel>_InLanes(crt_way, ...); else crt_<kernel>_Scalar(crt_way, ...);
//   crt_lanes.End(crt_way);  // (each way sets crt_way.iterations to its loop's count)
//
// Why: lanes are not faster on every CPU and for every loop. On an AMD EPYC with AVX2, per-lane
// gathers of 128-byte BVH nodes made PrimaryRays_ISPC trace at 0.27-0.38x of PrimaryRays_CPU, the
// LBVH_ISPC build took 2.0-2.8x LBVH_CPU's time (a divergent climb with per-lane atomics), and
// Bloom_ISPC ran at 0.51-0.57x of Bloom_CPU (a transpose of float4 pixels per tap). A user who asks
// for the SIMD class should never get less than the scalar one.
//
// So each kernel runs the way that has been faster here (MeasuredWays: lanes are way 1, the scalar
// loop way 0), per size class: loops within a factor of 4 of each other in iterations share one,
// and a call is taken to be of the size of the call before it (what is small may run best one way
// and what is large the other). Lanes run first; the very first call pays for touching memory and
// is not counted (whichever way it runs). The next call of a size class whose lanes have a time
// tries the scalar loop (twice where it was faster: MeasuredWays believes a try that wins on its
// second); after that the faster way runs, the other tried again after 16, 64, ... 1024 calls, or
// on the next call where the faster way's mean passes the other's (the work changed: the other is
// measured again, not taken on its old number). The means are kept from run to run (LaneMemory.h,
// per CPU model and ISPC target): a kernel's first call in the next run takes the way that was
// faster then, in the size class of the last call then, and where the other way's remembered mean
// is within a quarter of the verdict's new one, that way is measured again on the next call. Only on
// a machine that never ran it does a kernel called once or twice run in lanes.
// CROSSRT_ISPC_LANES=always keeps every kernel in lanes (as before this choice), =never runs every
// kernel's scalar loop (to test or compare it).
//
// Both ways compute the same loop nest: the differential tests compare each with the original.
// Their reductions may differ in the last bits, as the _CPU class's do between runs.
class LaneChoice {
 public:
  enum class Mode { Measure, Always, Never };

  struct Run {
    bool lanes;
    long long iterations;  // set by the way that runs: its loop's count
    std::chrono::steady_clock::time_point start;
    bool trying = false;    // the way that is not the verdict, tried
    int verdictCores = -1;  // when trying: what the verdict's last run ran on (1 all cores, 0 one core, -1 unknown)
    int cores = -1;         // what this run's loop ran on, as ParallelChoice tells it
    bool coresTried = false;  // ParallelChoice ran this loop on the cores that are not its verdict, to measure them
  };

  // `name` (a string literal: the generated code's Class::kernel) names the kernel in the log.
  explicit LaneChoice(const char* name = nullptr) : m_name(name) {
    for (auto& cores : m_verdictCores) cores.store(-1, std::memory_order_relaxed);
    if (Remembers()) LaneMemory::Get();  // made before this choice, so that it outlives it
  }

  // What this run measured goes to LaneMemory, for the next run's first calls: each way's mean, or
  // where it has none counted here (a kernel called once a run), its time on the run's first call,
  // or a try that won once and whose second try the run ended before (MeasuredWays::PendingTry).
  // A program that calls a kernel once so runs it in lanes in its first run, tries the scalar loop
  // in its second (the way with no time), and from its third takes the way whose first call was
  // faster, the other tried again every 16th run (the runs in a row that ran the verdict alone are
  // counted).
  ~LaneChoice() {
    if (!Remembers()) return;
    std::vector<RememberedWays> ways;
    const int last = m_lastSize.load(std::memory_order_relaxed);
    for (int size = 0; size < kLoopSizeClasses; ++size) {
      const MeasuredWays& measured = m_bySize[size];
      float ms[2];
      for (int w = 0; w < 2; ++w) {
        const float first = m_firstCallMs[size][w].load(std::memory_order_relaxed);
        ms[w] = measured.Mean(w) > 0.0f && !(measured.MeanRemembered(w) && first > 0.0f) ? measured.Mean(w) : first;
        if (measured.PendingTry(w) > 0.0f) ms[w] = measured.PendingTry(w);  // this run's latest time of that way
      }
      if (!(ms[1] > 0.0f || ms[0] > 0.0f)) continue;
      const int verdict = measured.Verdict();
      const bool ran = m_ran[size][0].load(std::memory_order_relaxed) || m_ran[size][1].load(std::memory_order_relaxed);
      const bool otherRan = verdict < 0 || m_ran[size][1 - verdict].load(std::memory_order_relaxed);
      const int runs = m_verdictOnlyRuns[size].load(std::memory_order_relaxed);
      ways.push_back({size, ms[1], ms[0], size == last, !ran ? runs : otherRan ? 0 : runs + 1});
    }
    if (!ways.empty()) LaneMemory::Get().Remember(m_name, std::move(ways));
  }

  Run Begin() {
    bool trying = false;
    const bool lanes = Choose(trying);
    // (A call is taken to be of the size of the call before it, as in Choose.)
    const int verdictCores = trying ? m_verdictCores[m_lastSize.load(std::memory_order_relaxed)].load(std::memory_order_relaxed) : -1;
    return {lanes, 0, std::chrono::steady_clock::now(), trying, verdictCores};
  }

  void End(const Run& run) {
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - run.start).count();
    // A run on the cores ParallelChoice was trying measured those cores, not this way: left out, and
    // not the cores the next try follows (ParallelChoice::Begin). A try of this choice's own counts
    // whatever it ran on, as the try is then over.
    const bool counted = !run.coresTried || run.trying;
    if (counted) Record(run.lanes, run.iterations, ms);
    if (counted && !run.trying && run.cores >= 0 && run.iterations >= 1)
      m_verdictCores[SizeClass(run.iterations)].store(run.cores, std::memory_order_relaxed);
    if (Logged()) {  // CROSSRT_ISPC_LANES_LOG=1: a line per call, to see what the choice does and why
      char lanes[32] = "not measured", scalar[32] = "not measured";
      if (Mean(1) >= 0.0f) std::snprintf(lanes, sizeof lanes, "%.4g", 1000.0 * Mean(1));
      if (Mean(0) >= 0.0f) std::snprintf(scalar, sizeof scalar, "%.4g", 1000.0 * Mean(0));
      std::fprintf(stderr, "crossrt: %s: %s%s, %lld iterations in %.3f ms on %s%s; mean ms per 1,000 iterations: lanes %s, scalar loop %s\n",
                   m_name != nullptr ? m_name : "a kernel", run.lanes ? "SIMD lanes" : "scalar loop", run.trying ? " (a try)" : "",
                   run.iterations, ms, run.cores == 1 ? "all cores" : run.cores == 0 ? "one core" : "the cores it chose",
                   counted ? "" : " (a try of the cores, not counted)", lanes, scalar);
    }
  }

  // CROSSRT_ISPC_LANES_LOG=1: each call's way, time and the means that chose it, on stderr.
  static bool Logged() {
    static const bool logged = [] {
      const char* v = std::getenv("CROSSRT_ISPC_LANES_LOG");
      return v != nullptr && std::strcmp(v, "1") == 0;
    }();
    return logged;
  }

  // The decision and the measurement apart, for tests; `trying` tells a try of the way that is not
  // the verdict.
  bool Choose() {
    bool trying = false;
    return Choose(trying);
  }
  bool Choose(bool& trying) {
    trying = false;
    if (LanesMode() != Mode::Measure) return LanesMode() == Mode::Always;
    if (Remembers() && !m_recalled.exchange(true, std::memory_order_relaxed))  // the first call: what the last run measured
      for (const RememberedWays& remembered : LaneMemory::Get().Recall(m_name)) {
        const int size = remembered.sizeClass % kLoopSizeClasses;
        m_bySize[size].Seed(remembered.lanesMs, remembered.scalarMs, remembered.verdictOnlyRuns);
        m_verdictOnlyRuns[size].store(remembered.verdictOnlyRuns, std::memory_order_relaxed);
        if (remembered.last) m_lastSize.store(size, std::memory_order_relaxed);
      }
    MeasuredWays& ways = m_bySize[m_lastSize.load(std::memory_order_relaxed)];
    const float scalar = ways.Mean(0), lanes = ways.Mean(1);
    if (lanes < 0.0f) return true;  // first the lanes, the way this class is for
    if (scalar < 0.0f) {  // then the scalar loop, once, to compare
      ways.Try();
      trying = true;
      return false;
    }
    trying = ways.TimeToTry();
    return ways.Verdict() == 0 ? trying : !trying;  // the faster way, the other now and then
  }

  void Record(bool lanes, long long iterations, double ms) {
    if (iterations < 1 || LanesMode() != Mode::Measure) return;  // (an early return ran no loop)
    const int size = SizeClass(iterations);
    m_lastSize.store(size, std::memory_order_relaxed);
    m_ran[size][lanes ? 1 : 0].store(true, std::memory_order_relaxed);
    if (!m_warm.exchange(true, std::memory_order_relaxed)) {  // the first run touched the memory: not counted here,
      m_firstCallMs[size][lanes ? 1 : 0].store(float(ms / double(iterations)), std::memory_order_relaxed);  // but kept for the next run
      return;
    }
    m_bySize[size].Record(lanes, float(ms / double(iterations)));
  }

  // The mean ms per iteration of a way in the size class of the last call (-1 before the first).
  float Mean(int way) const { return m_bySize[m_lastSize.load(std::memory_order_relaxed)].Mean(way); }

  static int SizeClass(long long iterations) { return LoopSizeClass(iterations); }

  // CROSSRT_ISPC_LANES: always, never, or (unset) measure.
  static Mode LanesMode() {
    static const Mode mode = [] {
      const char* v = std::getenv("CROSSRT_ISPC_LANES");
      if (v != nullptr && std::strcmp(v, "always") == 0) return Mode::Always;
      if (v != nullptr && std::strcmp(v, "never") == 0) return Mode::Never;
      return Mode::Measure;
    }();
    return mode;
  }

 private:
  // Whether this choice keeps what it measures for the next run (a named kernel's, while measuring).
  bool Remembers() const { return m_name != nullptr && LanesMode() == Mode::Measure; }

  MeasuredWays m_bySize[kLoopSizeClasses];
  std::atomic<float> m_firstCallMs[kLoopSizeClasses][2] = {};  // per size class and way: the run's first call, ms per iteration
  std::atomic<bool> m_ran[kLoopSizeClasses][2] = {};           // per size class and way: whether it ran in this run
  std::atomic<int> m_verdictOnlyRuns[kLoopSizeClasses] = {};   // per size class: earlier runs in a row that ran the verdict alone
  std::atomic<bool> m_recalled{false};
  std::atomic<int> m_verdictCores[kLoopSizeClasses];  // per size class: what the verdict's last run ran on, -1 before one
  std::atomic<int> m_lastSize{0};
  std::atomic<bool> m_warm{false};
  const char* m_name;
};

// `v.push_back(x)` in a kernel whose loop runs on all cores: the generated code calls
// crossrt::Locked(v).push_back(x), one append at a time. The order of the elements is the order the
// threads arrive in, as on the GPU.
template <typename Vector>
struct LockedAppend {
  Vector& vector;
  template <typename T>
  void push_back(T&& value) {
#pragma omp critical(crossrt_append)
    vector.push_back(std::forward<T>(value));
  }
};

template <typename Vector>
LockedAppend<Vector> Locked(Vector& vector) {
  return LockedAppend<Vector>{vector};
}

}  // namespace crossrt
