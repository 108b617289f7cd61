// The CPU backend's parallel loops: crossrt::ParallelFor runs a loop's iterations in chunks on the
// calling thread and on a pool of worker threads, and returns as soon as every chunk is done,
// without waiting for workers that never started (header only).
//
// Why not `#pragma omp parallel for`: an OpenMP parallel region ends at a barrier that every thread
// of its team must reach, including threads the scheduler has not yet run. On a machine whose cores
// other programs keep busy, a woken worker waits for a time slice (milliseconds) before it can even
// see that there is no work left, and the loop waits with it: with a busy thread beside each of 2
// cores (AMD EPYC, bench_lbvh --load 2), each kernel's first parallel call in the LBVH build took
// 5-12 ms where the loop takes 0.01-0.5 ms on one core; on a 16-core Xeon beside 16 busy threads,
// builds of 47k-202k triangles took 2.6-11.5x the single-threaded original's time. Embree's builds
// (TBB) did not collapse: there the calling thread runs the tasks no worker has taken.
//
// So here: the chunks are handed out from one counter; the caller takes chunks too, and once none
// is left it waits only for the chunks workers have taken and not finished. A worker that wakes
// after the loop finds nothing to take and sleeps again. Loops inside a loop's body (and loops in
// an OpenMP parallel region) run on their thread. While one thread's loop runs on the pool, another
// thread's loop runs on its own thread alone. The iterations are what the loop's own code makes of
// [first, last), so a loop computes the same thing whichever thread runs each chunk. What the
// pool cannot save is a chunk whose worker loses its core while it runs it: the loop waits for it.
//
// The pool has omp_get_max_threads() - 1 workers (OMP_NUM_THREADS is honoured), started on the first
// parallel loop. A worker that finds no work spins for about 20 us, then sleeps on a condition
// variable (as libgomp's threads do at once under OMP_WAIT_POLICY=passive), so that an idle pool
// leaves the cores to other programs. The pool is never destroyed: its threads end with the process.
#pragma once

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace crossrt {

namespace detail {

// Whether this thread is running a chunk of a pool loop (a loop inside it then runs on this thread).
inline bool& InPoolChunk() {
  static thread_local bool inChunk = false;
  return inChunk;
}

class LoopPool {
 public:
  // The chunks of one loop: Call(body, first, last) runs chunks [first, last) of the loop.
  using Call = void (*)(void* body, long long first, long long last);

  static LoopPool& Instance() {
    static LoopPool* pool = new LoopPool(std::max(1, omp_get_max_threads()) - 1);  // never destroyed (see above)
    return *pool;
  }

  int Workers() const { return int(m_workers.size()); }

  // Runs chunks [0, chunks) with call(body, ...) on this thread and the workers; returns when all
  // are done, rethrowing the first exception a chunk threw. False (nothing run) when another
  // thread's loop holds the pool.
  bool Run(long long chunks, Call call, void* body) {
    std::unique_lock<std::mutex> owner(m_owner, std::try_to_lock);
    if (!owner.owns_lock()) return false;
    m_call.store(call, std::memory_order_relaxed);
    m_body.store(body, std::memory_order_relaxed);
    m_chunks.store(chunks, std::memory_order_relaxed);
    m_done.store(0, std::memory_order_relaxed);
    m_failure = nullptr;
    const uint64_t generation = (Generation(m_claim.load(std::memory_order_relaxed)) + 1) & kGenerations;  // (wraps after 2^24 loops)
    m_claim.store(generation << kIndexBits, std::memory_order_seq_cst);  // publishes the loop (seq_cst: see Work)
    if (m_sleeping.load(std::memory_order_seq_cst) > 0) {
      std::lock_guard<std::mutex> lock(m_sleep);
      m_wake.notify_all();
    }
    TakeChunks(generation);
    // Every chunk is taken: wait for those workers are still running (not for workers that never
    // started), yielding the core after a short spin.
    for (int spins = 0; m_done.load(std::memory_order_acquire) < chunks; ++spins)
      if (spins > 64) std::this_thread::yield();
    if (m_failure) std::rethrow_exception(m_failure);
    return true;
  }

 private:
  static constexpr int kIndexBits = 40;  // the claim word: generation above, next chunk below
  static constexpr uint64_t kGenerations = (uint64_t(1) << (64 - kIndexBits)) - 1;
  static uint64_t Generation(uint64_t claim) { return claim >> kIndexBits; }
  static long long Index(uint64_t claim) { return static_cast<long long>(claim & ((uint64_t(1) << kIndexBits) - 1)); }

  explicit LoopPool(int workers) {
    for (int w = 0; w < workers; ++w) m_workers.emplace_back([this] { Work(); });
    for (auto& t : m_workers) t.detach();
  }

  // Takes chunks of loop `generation` one at a time until none is left (or a newer loop began).
  void TakeChunks(uint64_t generation) {
    uint64_t claim = m_claim.load(std::memory_order_acquire);
    while (Generation(claim) == generation && Index(claim) < m_chunks.load(std::memory_order_relaxed)) {
      if (!m_claim.compare_exchange_weak(claim, claim + 1, std::memory_order_acq_rel, std::memory_order_acquire)) continue;
      // Taken: the loop cannot finish (nor another begin) before this chunk is done, so its call
      // and body are this loop's.
      const long long chunk = Index(claim);
      bool& inChunk = InPoolChunk();
      const bool outer = inChunk;
      inChunk = true;
      try {
        m_call.load(std::memory_order_relaxed)(m_body.load(std::memory_order_relaxed), chunk, chunk + 1);
      } catch (...) {
        std::lock_guard<std::mutex> lock(m_sleep);
        if (!m_failure) m_failure = std::current_exception();
      }
      inChunk = outer;
      m_done.fetch_add(1, std::memory_order_acq_rel);
      claim = m_claim.load(std::memory_order_acquire);
    }
  }

  void Work() {
    uint64_t seen = 0;
    while (true) {
      uint64_t generation = Generation(m_claim.load(std::memory_order_acquire));
      const auto spinUntil = std::chrono::steady_clock::now() + std::chrono::microseconds(20);
      while (generation == seen && std::chrono::steady_clock::now() < spinUntil) generation = Generation(m_claim.load(std::memory_order_acquire));
      if (generation == seen) {
        // Counted as sleeping before the claim is read again, and the loop published before the
        // count is read (both seq_cst): either the worker sees the loop or its caller wakes it.
        std::unique_lock<std::mutex> lock(m_sleep);
        m_sleeping.fetch_add(1, std::memory_order_seq_cst);
        m_wake.wait(lock, [&] { return Generation(m_claim.load(std::memory_order_seq_cst)) != seen; });
        m_sleeping.fetch_sub(1, std::memory_order_relaxed);
        generation = Generation(m_claim.load(std::memory_order_acquire));
      }
      seen = generation;
      TakeChunks(generation);
    }
  }

  std::vector<std::thread> m_workers;
  std::mutex m_owner;  // held by the thread whose loop runs on the pool
  std::atomic<uint64_t> m_claim{0};
  std::atomic<long long> m_chunks{0};
  std::atomic<long long> m_done{0};
  std::atomic<Call> m_call{nullptr};
  std::atomic<void*> m_body{nullptr};
  std::exception_ptr m_failure;  // (under m_sleep)
  std::mutex m_sleep;
  std::condition_variable m_wake;
  std::atomic<int> m_sleeping{0};
};

}  // namespace detail

// Whether a loop here would run inside another parallel loop (a pool chunk or an OpenMP region),
// and so on this thread alone.
inline bool InParallelLoop() { return detail::InPoolChunk() || omp_in_parallel(); }

// CROSSRT_CPU_LOOPS=openmp: ParallelFor hands its chunks to an OpenMP loop instead of the pool (as
// the generated code did before the pool), to compare the two.
inline bool OpenMPLoops() {
  static const bool openmp = [] {
    const char* v = std::getenv("CROSSRT_CPU_LOOPS");
    return v != nullptr && std::string(v) == "openmp";
  }();
  return openmp;
}

// The threads a parallel loop runs on: the pool's workers and the calling thread.
inline int LoopThreads() { return detail::LoopPool::Instance().Workers() + 1; }

// Runs body(first, last) over [begin, end) in chunks of `grain` iterations or more (see below): on
// the pool and this thread when `parallel` (and not inside another parallel loop), else once, on
// this thread, over the whole range. The generated loops call it as
//   crossrt::ParallelFor<int>(crt_loop.parallel, 0, n, 1024, [&](int crt_first, int crt_last) {
//     for (int i = crt_first; i < crt_last; i++) { ...the loop's body... }
//   });
template <typename T, typename Body>
void ParallelFor(bool parallel, T begin, T end, long long grain, Body&& body) {
  if (!(begin < end)) return;
  const long long count = static_cast<long long>(end - begin);
  // At most kChunksPerThread chunks a thread: enough to even out iterations of unequal cost, and
  // few enough that claiming chunks and merging reductions (a lock per chunk) stay cheap. With
  // chunks of 1024 for 1M particles, Particles_CPU (four reductions) ran at 1.74-1.78x of the
  // original on 2 threads; with this limit, at 2.41-2.47x (AMD EPYC, quiet).
  constexpr long long kChunksPerThread = 32;
  const long long threads = parallel ? LoopThreads() : 1;
  grain = std::max({1LL, grain, (count + threads * kChunksPerThread - 1) / (threads * kChunksPerThread)});
  const long long chunks = (count + grain - 1) / grain;
  if (parallel && chunks > 1 && !InParallelLoop() && threads > 1) {
    struct Chunks {
      Body& body;
      T begin, end;
      long long grain;
      static void Run(void* self, long long first, long long last) {
        auto& c = *static_cast<Chunks*>(self);
        const T from = static_cast<T>(c.begin + static_cast<T>(first * c.grain));
        const T to = last * c.grain >= static_cast<long long>(c.end - c.begin) ? c.end : static_cast<T>(c.begin + static_cast<T>(last * c.grain));
        c.body(from, to);
      }
    } chunked{body, begin, end, grain};
    if (OpenMPLoops()) {  // to compare
#pragma omp parallel for schedule(dynamic, 1)
      for (long long chunk = 0; chunk < chunks; ++chunk) Chunks::Run(&chunked, chunk, chunk + 1);
      return;
    }
    if (detail::LoopPool::Instance().Run(chunks, &Chunks::Run, &chunked)) return;
  }
  body(begin, end);
}

// The reductions' operations, for scalars and LiteMath vectors alike (min and max found by ADL).
struct Sum {
  template <typename T>
  T operator()(const T& a, const T& b) const { return a + b; }
};
struct Minimum {
  template <typename T>
  T operator()(const T& a, const T& b) const {
    using std::min;
    return min(a, b);
  }
};
struct Maximum {
  template <typename T>
  T operator()(const T& a, const T& b) const {
    using std::max;
    return max(a, b);
  }
};

// The reductions of one ParallelFor (a generated loop's crt_reductions): each chunk reduces into
// parts of its own, started from zero (sums) or from the total so far (min, max: taking a value
// twice changes nothing), and merges them into the totals under one lock when its iterations are
// done. Whole values (scalars, LiteMath vectors) and arrays of them (coefs[k] += x) alike.
class LoopReductions {
 public:
  template <typename T>
  static void StartFromZero(T& part) { part = T(); }
  template <typename T, size_t N>
  static void StartFromZero(T (&part)[N]) { std::fill(part, part + N, T()); }

  template <typename T>
  void StartFromTotal(T& part, const T& total) {
    const std::lock_guard<std::mutex> lock(m_merging);
    Copy(part, total);
  }

  // total = op(total, part), element by element for arrays.
  template <typename T, typename Op>
  void Merge(T& total, const T& part, Op op) {
    const std::lock_guard<std::mutex> lock(m_merging);
    Combine(total, part, op);
  }

 private:
  template <typename T>
  static void Copy(T& to, const T& from) { to = from; }
  template <typename T, size_t N>
  static void Copy(T (&to)[N], const T (&from)[N]) { std::copy(from, from + N, to); }
  template <typename T, typename Op>
  static void Combine(T& total, const T& part, Op op) { total = op(total, part); }
  template <typename T, size_t N, typename Op>
  static void Combine(T (&total)[N], const T (&part)[N], Op op) {
    for (size_t i = 0; i < N; ++i) total[i] = op(total[i], part[i]);
  }

  std::mutex m_merging;
};

}  // namespace crossrt
