// The CPU backend's versions of library calls in control functions, and of push_back in kernels
// (header only; OpenMP).
#pragma once
#include "SortKey.h"

#include <omp.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

namespace crossrt {

// Stable LSD radix sort of n records of key.strideWords words, on all cores: per pass of 11 bits
// (three passes cover a 32-bit key), each thread counts the digits of its slice, the counts are
// scanned in (digit, thread) order, and each thread moves its slice's records to their places. A
// pass whose digit is the same in every record moves nothing and is skipped (keys below 2^22 take
// two passes).
inline void RadixSortWords(uint32_t* records, size_t n, const SortKey& key) {
  constexpr uint32_t kDigitBits = 11, kDigits = 1u << kDigitBits;
  const size_t stride = key.strideWords;
  // The scratch copy is kept for the next sort of this thread: a fresh one would be zeroed (and
  // its pages faulted in) on every call, only for the sort to overwrite it.
  static thread_local std::vector<uint32_t> scratch;
  if (scratch.size() < n * stride) scratch.resize(n * stride);
  uint32_t* src = records;
  uint32_t* dst = scratch.data();
  // Below 2^15 records, waking the other threads costs more than they save: with this, the LBVH
  // build of the 992-triangle teapot went from 1.1x to 0.8x of Embree LOW's time.
  const int threads = n < (size_t(1) << 15) ? 1 : omp_get_max_threads();
  std::vector<size_t> counts(size_t(threads) * kDigits);
  for (uint32_t shift = 0; shift < 32; shift += kDigitBits) {
    std::fill(counts.begin(), counts.end(), 0);
    bool oneDigit = false;
#pragma omp parallel num_threads(threads)
    {
      const int t = omp_get_thread_num(), used = omp_get_num_threads();
      const size_t begin = n * t / used, end = n * (t + 1) / used;
      size_t* mine = &counts[size_t(t) * kDigits];
      for (size_t i = begin; i < end; ++i) ++mine[(SortableBits(src[i * stride + key.keyWord], key) >> shift) & (kDigits - 1)];
#pragma omp barrier
#pragma omp single
      {
        size_t position = 0;
        for (uint32_t digit = 0; digit < kDigits; ++digit) {
          size_t inDigit = 0;
          for (int u = 0; u < used; ++u) {
            const size_t c = counts[size_t(u) * kDigits + digit];
            counts[size_t(u) * kDigits + digit] = position;
            position += c;
            inDigit += c;
          }
          oneDigit = oneDigit || inDigit == n;
        }
      }  // (the implicit barrier publishes oneDigit)
      if (!oneDigit)
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
    if (!oneDigit) std::swap(src, dst);
  }
  if (src != records) {  // an odd number of passes moved records: the result is in scratch
#pragma omp parallel for num_threads(threads) schedule(static)
    for (long long i = 0; i < static_cast<long long>(n * stride); ++i) records[i] = src[i];
  }
}

// std::sort of a range the translator recognized (see SortKey), on all cores.
template <typename Iterator>
void RadixSort(Iterator first, Iterator last, const SortKey& key) {
  const auto n = last - first;
  if (n <= 1) return;
  static_assert(sizeof(*first) % 4 == 0, "records of whole 32-bit words");
  RadixSortWords(reinterpret_cast<uint32_t*>(&*first), size_t(n), key);
}

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
