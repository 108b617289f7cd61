// One kernel from start to end: its loop nest, parameters, writes and reductions, the GLSL of its body
// through the printer, and the CPU copy with its OpenMP pragma. Takes a kernel's method; adds a Kernel
// to the model.
#pragma once
#include "analyse/AnalysisContext.h"

namespace crossrt::engine {

// The pass: kernel `md`, whose body `def` holds, into a Kernel of the model (GLSL, CPU copy, bindings).
void AnalyzeKernel(Context& c, const CXXMethodDecl* md, const FunctionDecl* def);

}  // namespace crossrt::engine
