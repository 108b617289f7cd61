// Atomic read-modify-write operations for kernels, in plain C++. The original class runs them on
// one thread, the translated CPU class on all cores (GCC/Clang __atomic builtins), and the
// translated Vulkan class as GLSL atomics (atomicAdd and the like with device scope).
//
// The target must live in device memory: an element (or a field of an element) of a std::vector
// data member, a plain data member, or an element of a kernel's pointer parameter. A local
// variable or a helper's reference parameter is a per-thread copy on the GPU; the translator
// reports it.
//
// Ordering: each operation is an acquire-release fence at device scope, as a C++
// memory_order_acq_rel atomic. What a thread wrote before an atomic is visible to another thread
// after that thread's atomic on the same target read the value it left. This is what a
// bottom-up pass needs ("the second child to arrive finishes the parent"). The translator makes
// the buffers of a kernel that calls them coherent.
#pragma once

#include <cstdint>

namespace crossrt {

// Each returns the value the target held before.
inline uint32_t AtomicAdd(uint32_t& target, uint32_t value) { return __atomic_fetch_add(&target, value, __ATOMIC_ACQ_REL); }
inline int32_t AtomicAdd(int32_t& target, int32_t value) { return __atomic_fetch_add(&target, value, __ATOMIC_ACQ_REL); }
inline uint32_t AtomicAnd(uint32_t& target, uint32_t value) { return __atomic_fetch_and(&target, value, __ATOMIC_ACQ_REL); }
inline int32_t AtomicAnd(int32_t& target, int32_t value) { return __atomic_fetch_and(&target, value, __ATOMIC_ACQ_REL); }
inline uint32_t AtomicOr(uint32_t& target, uint32_t value) { return __atomic_fetch_or(&target, value, __ATOMIC_ACQ_REL); }
inline int32_t AtomicOr(int32_t& target, int32_t value) { return __atomic_fetch_or(&target, value, __ATOMIC_ACQ_REL); }
inline uint32_t AtomicXor(uint32_t& target, uint32_t value) { return __atomic_fetch_xor(&target, value, __ATOMIC_ACQ_REL); }
inline int32_t AtomicXor(int32_t& target, int32_t value) { return __atomic_fetch_xor(&target, value, __ATOMIC_ACQ_REL); }
inline uint32_t AtomicExchange(uint32_t& target, uint32_t value) { return __atomic_exchange_n(&target, value, __ATOMIC_ACQ_REL); }
inline int32_t AtomicExchange(int32_t& target, int32_t value) { return __atomic_exchange_n(&target, value, __ATOMIC_ACQ_REL); }

// Minimum and maximum: a compare-exchange loop on the CPU (GCC has no fetch_min before 13).
template <typename T>
inline T AtomicMinMaxLoop(T& target, T value, bool takeMin)
{
  T old = __atomic_load_n(&target, __ATOMIC_ACQUIRE);
  while ((takeMin ? value < old : value > old) &&
         !__atomic_compare_exchange_n(&target, &old, value, true, __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE)) {
  }
  return old;
}
inline uint32_t AtomicMin(uint32_t& target, uint32_t value) { return AtomicMinMaxLoop(target, value, true); }
inline int32_t AtomicMin(int32_t& target, int32_t value) { return AtomicMinMaxLoop(target, value, true); }
inline uint32_t AtomicMax(uint32_t& target, uint32_t value) { return AtomicMinMaxLoop(target, value, false); }
inline int32_t AtomicMax(int32_t& target, int32_t value) { return AtomicMinMaxLoop(target, value, false); }

// Writes `desired` when the target holds `expected`; returns what it held (== expected: written).
inline uint32_t AtomicCompareExchange(uint32_t& target, uint32_t expected, uint32_t desired)
{
  __atomic_compare_exchange_n(&target, &expected, desired, false, __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE);
  return expected;
}
inline int32_t AtomicCompareExchange(int32_t& target, int32_t expected, int32_t desired)
{
  __atomic_compare_exchange_n(&target, &expected, desired, false, __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE);
  return expected;
}

}  // namespace crossrt
