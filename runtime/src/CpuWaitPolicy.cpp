// Compiled into every executable that links crossrt::cpu_runtime (the _CPU and _ISPC classes'
// runtime): at program start, before any shared library initialises, it sets OMP_WAIT_POLICY to
// "passive" unless the environment already names a policy.
//
// Why: libgomp's default lets a thread that finished its part of a parallel loop spin for a while
// (GOMP_SPINCOUNT, about 300,000 pauses) before it sleeps. The generated kernels run each loop
// either on all cores or on the calling thread (crossrt::ParallelChoice in CpuParallel.h). When
// another program keeps a core busy, a worker still spinning after the last parallel loop holds a
// core that the calling thread, running the next loop alone, then has to share with the other
// program. With one busy thread beside bench_lbvh on 2 cores (AMD EPYC), the LBVH_CPU build of the
// 75,408-triangle bunny took 41 and 68 ms in two runs of four with the default policy (14-17 ms
// in the others; the single-threaded original 15-21 ms), and 12.1-18.3 ms in four runs of four
// with passive waits. Quiet, the two policies build at the same speed. (Those loops were OpenMP
// loops then; since the generated loops run on CrossRT's own pool (CpuLoops.h), the policy is
// for the OpenMP regions the program runs itself, and for CROSSRT_CPU_LOOPS=openmp.)
//
// libgomp reads the variable once, in its own initialiser, so it is set from the executable's
// .preinit_array, which the dynamic loader runs before every shared library's initialiser. A
// shared library cannot have one: a program that loads translated classes from a shared library
// (a Python module) sets OMP_WAIT_POLICY=passive itself. Set it to "active" to keep libgomp's spinning.
#include <cstdlib>

namespace {

void CrossRTPassiveOpenMPWaits(int, char**, char**) { setenv("OMP_WAIT_POLICY", "passive", /*overwrite=*/0); }

__attribute__((section(".preinit_array"), used)) void (*const kSetWaitPolicy)(int, char**, char**) = CrossRTPassiveOpenMPWaits;

}  // namespace
