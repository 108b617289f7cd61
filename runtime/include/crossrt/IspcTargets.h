// The ISPC targets the generated _ISPC classes are compiled for, and which of them this CPU runs
// (header only): IspcPick (IspcSupport.h) chooses among them, and LaneMemory names the one in use.
#pragma once

#include <cstdlib>
#include <cstring>
#include <iterator>
#include <string>

namespace crossrt {

// The ISPC targets every generated class is compiled for, in the order of CrossRT.cmake's
// CROSSRT_ISPC_TARGETS, and whether this CPU runs each.
inline const char* const kIspcTargets[] = {"sse4", "avx2", "avx512skx"};
inline bool CpuRunsIspcTarget(int index) {
  __builtin_cpu_init();
  switch (index) {
    case 0: return __builtin_cpu_supports("sse4.2");
    // (ISPC compiles its avx2 target for a Haswell, whose BMI2 and F16C its code may use.)
    case 1: return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2") && __builtin_cpu_supports("f16c");
    default:
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512cd") &&
             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl");
  }
}

// The widest of kIspcTargets this CPU runs, as an index into it (-1 for none), as ISPC's own
// dispatch would pick it.
inline int WidestIspcTarget() {
  for (int i = int(std::size(kIspcTargets)) - 1; i >= 0; --i)
    if (CpuRunsIspcTarget(i)) return i;
  return -1;
}

// The target the _ISPC classes run: CROSSRT_ISPC_TARGET where it names one (IspcPick checks that it
// is one this CPU runs), else the widest this CPU runs.
inline std::string IspcTargetInUse() {
  const char* forced = std::getenv("CROSSRT_ISPC_TARGET");
  if (forced && *forced && std::strcmp(forced, "auto") != 0) return forced;
  const int widest = WidestIspcTarget();
  return widest >= 0 ? kIspcTargets[widest] : "none";
}

}  // namespace crossrt
