// Compiled into every executable that links crossrt::cpu_runtime: one reference to
// libcrossrt_openmp_waits.so, so that the linker (--as-needed) keeps the library, whose initialiser
// makes libgomp's threads sleep after a parallel region (OpenMPWaits.cpp says why and how).
extern "C" int crossrt_openmp_waits_set;

namespace {

[[gnu::used]] int* const kKeepsPassiveOpenMPWaits = &crossrt_openmp_waits_set;

}  // namespace
