// The naming conventions of the paper's classes, spelled out once. Kernels are the methods named kernel_*
// (RTV, "ray tracing vectorization": the control function loops over threads and the kernel is the code
// of one thread, given tid/tidX/tidY/tidZ) or kernel1D_..kernel3D_* (IPV, "image processing
// vectorization": the kernel holds its own loop nest, whose iterations become the threads).
#include "analyse/Naming.h"

#include <algorithm>

using namespace clang;

namespace crossrt::engine {

bool IsKernelName(StringRef n) {
  return n.starts_with("kernel_") || n.starts_with("kernel1D_") || n.starts_with("kernel2D_") || n.starts_with("kernel3D_");
}

unsigned IpvDims(StringRef n) {
  if (n.starts_with("kernel1D_")) return 1;
  if (n.starts_with("kernel2D_")) return 2;
  if (n.starts_with("kernel3D_")) return 3;
  return 0;
}

bool IsThreadIdName(StringRef n) { return n == "tid" || n == "tidX" || n == "tidY" || n == "tidZ"; }

unsigned ThreadAxis(StringRef n) { return n == "tidY" ? 1 : n == "tidZ" ? 2 : 0; }

}  // namespace crossrt::engine
