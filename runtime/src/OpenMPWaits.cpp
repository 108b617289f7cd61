// libcrossrt_openmp_waits.so: a library with nothing to call. While a program that links the _CPU or
// _ISPC classes' runtime (crossrt::cpu_runtime) loads, it sets OMP_WAIT_POLICY to "passive" unless
// the environment names a policy, before libgomp reads it: libgomp's threads then sleep at once
// after a parallel region instead of spinning.
//
// Why: libgomp's default lets a thread that finished its part of a parallel region spin for
// GOMP_SPINCOUNT (300,000) pauses before it sleeps: on an AMD EPYC with 2 threads, 7-10 ms of a
// core after every region. A program's own `#pragma omp parallel for` (a user's loop, Embree's
// packet calls in bench_lbvh) then takes that core from the translated class called next, whose
// loops run on CrossRT's pool (CpuLoops.h): PrimaryRays_ISPC traced the teapot's 1024x1024 rays at
// 1.37-1.41x of Embree's rtcIntersect1 right after an OpenMP loop, and at 1.77-1.86x with passive
// waits (CROSSRT_ISPC_TARGET=avx2, bench_lbvh). Under load it is worse: a spinning worker holds a
// core that the calling thread, running the next loop alone, has to share with another program.
//
// How: libgomp reads the variable once, in its initialiser. The dynamic loader runs a library's
// initialiser after those of the libraries it needs, and of libraries that do not need each other,
// the one later in the program's list first. CMake's target for OpenMP links this library, so it
// comes after libgomp in every program's list and its initialiser runs first.
// (A .preinit_array in the program, as CrossRT had before, does not do: glibc's own initialiser
// runs after it and resets the environment to the one the kernel passed. libgomp then kept
// spinning with OMP_WAIT_POLICY unset, while OMP_DISPLAY_ENV still printed 'PASSIVE', its
// default.) The test runtime.passive_openmp_waits reads the spin count libgomp took.
//
// Programs refer to crossrt_openmp_waits_set (OpenMPWaitsUse.cpp, compiled into each executable)
// so that the linker's --as-needed keeps the library. A program that loads translated classes from
// a shared library after libgomp has started (a Python module) sets OMP_WAIT_POLICY itself. Set it
// to "active" to keep libgomp's spinning. Child processes inherit the variable.
#include <cstdlib>

extern "C" {
// 1 when this library set OMP_WAIT_POLICY, 0 when the environment named a policy.
__attribute__((visibility("default"))) int crossrt_openmp_waits_set = 0;
}

namespace {

__attribute__((constructor)) void CrossRTPassiveOpenMPWaits()
{
  if (std::getenv("OMP_WAIT_POLICY") != nullptr) return;  // the user's choice
  setenv("OMP_WAIT_POLICY", "passive", /*overwrite=*/0);
  crossrt_openmp_waits_set = 1;
}

}  // namespace
