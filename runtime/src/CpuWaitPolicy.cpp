// Compiled into every executable that links crossrt::cpu_runtime (the _CPU and _ISPC classes'
// runtime): at program start, before any shared library initialises, it sets OMP_WAIT_POLICY to
// "passive" unless the environment already names a policy.
//
// Why: libgomp's default lets a thread that finished its part of a parallel loop spin for a while
// (GOMP_SPINCOUNT, about 300,000 pauses) before it sleeps. On a machine where another program keeps
// a core busy, the scheduler takes a spinning worker off its core, and the next parallel loop waits
// for it a whole time slice, at its start and at its closing barrier. A translated class's
// control function runs one parallel loop per kernel call, so it pays that wait per kernel. With
// one busy thread beside bench_lbvh on 2 cores (AMD EPYC), LBVH_CPU's build of the 11,102-triangle
// dragon took 4.6 ms with the default policy against 1.6 ms passive (1.1 and 1.2 ms on the quiet
// machine), where Embree LOW stayed at 1.4 ms. Sleeping threads are woken at once instead.
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
