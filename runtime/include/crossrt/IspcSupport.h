// What the ISPC backend's generated classes call around their ISPC kernels (header only): passing
// C++ objects to the ISPC functions (whose header declares its own structs of the same layout),
// and choosing the compiled target, for tests that force one.
#pragma once

#include "crossrt/ClassName.h"
#include "crossrt/IspcTargets.h"
#include "crossrt/LaneMemory.h"
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace crossrt {

// A C++ pointer as the ISPC header's pointer type (LiteMath::float4* as ispc::float4*): the
// layouts are the same, which the generated structs' padding ensures.
template <class To, class From>
To IspcPointer(From* p) {
  return reinterpret_cast<To>(const_cast<std::remove_const_t<From>*>(p));
}
// A C++ object as the ISPC header's type of the same layout, by reference.
template <class To, class From>
const To& IspcReference(const From& value) {
  static_assert(sizeof(To) == sizeof(From), "the ISPC struct and the C++ type differ in size");
  return *reinterpret_cast<const To*>(&value);
}
// A member copied into the ISPC class data.
template <class To, class From>
void IspcCopy(To& to, const From& from) {
  static_assert(sizeof(To) == sizeof(From), "the ISPC struct and the C++ type differ in size");
  std::memcpy(static_cast<void*>(&to), static_cast<const void*>(&from), sizeof to);
}

// An Image2D as LiteMath.isph's crt_Image_<T>: its texels (read and written in place) and size.
template <class To, class Image>
To IspcImage(const Image& image) {
  To to;
  to.data = IspcPointer<decltype(to.data)>(image.data());
  to.width = image.width();
  to.height = image.height();
  return to;
}

// The object a composed member (shared_ptr, unique_ptr or plain pointer) holds, or null.
template <class T>
T* IspcHeld(T* p) {
  return p;
}
template <class Smart>
auto* IspcHeld(const Smart& p) {
  return p.get();
}

// The function an ISPC kernel runs: the version of the widest of kIspcTargets this CPU runs (the
// target ISPC's own `dispatch` would pick), unless CROSSRT_ISPC_TARGET names one of kIspcTargets,
// whose version of the function it then is. A name it does not know, or a target this CPU cannot
// run, throws with what to set instead.
//
// Why not `dispatch`: ISPC's dispatch asks the CPU with CPUID at its first call in each module, and
// in a virtual machine each CPUID leaves to the hypervisor: on an AMD EPYC VM (Zen 5) a CPUID took
// 6.5 us, and an _ISPC class's first kernel call 27 us more than its next. WidestIspcTarget reads
// what the C runtime learnt as the program started.
template <class F>
F IspcPick(F dispatch, std::initializer_list<F> perTarget) {
  const char* forced = std::getenv("CROSSRT_ISPC_TARGET");
  if (!forced || !*forced || std::string(forced) == "auto") {
    const int widest = WidestIspcTarget();
    // (A CPU without SSE4.2: ISPC's dispatch says so.)
    return widest >= 0 && widest < int(perTarget.size()) ? perTarget.begin()[widest] : dispatch;
  }
  std::string known;
  for (int i = 0; i < int(std::size(kIspcTargets)); ++i) {
    known += std::string(i ? ", " : "") + kIspcTargets[i];
    if (forced != std::string(kIspcTargets[i])) continue;
    if (!CpuRunsIspcTarget(i)) throw std::runtime_error(std::string("CROSSRT_ISPC_TARGET=") + forced + ": this CPU cannot run that ISPC target");
    return perTarget.begin()[i];
  }
  throw std::runtime_error(std::string("CROSSRT_ISPC_TARGET=") + forced + " is not a target the ISPC classes are built for (" + known + ", or auto)");
}

// The lane choices an earlier run left (LaneMemory), read as the program starts rather than at its
// first kernel call, which would pay the tenth of a millisecond it takes. Every program with an
// _ISPC class includes this header; the _CPU classes do not.
inline const bool kLaneMemoryRead = (LaneMemory::Get(), true);

}  // namespace crossrt
