// The naming conventions of the paper's classes, spelled out once. Kernels are the methods named kernel_*
// (RTV, "ray tracing vectorization": the control function loops over threads and the kernel is the code
// of one thread, given tid/tidX/tidY/tidZ) or kernel1D_..kernel3D_* (IPV, "image processing
// vectorization": the kernel holds its own loop nest, whose iterations become the threads).
#pragma once
#include "analyse/AnalysisContext.h"

namespace crossrt::engine {

bool IsKernelName(StringRef n);

unsigned IpvDims(StringRef n);

bool IsThreadIdName(StringRef n);

unsigned ThreadAxis(StringRef n);

}  // namespace crossrt::engine
