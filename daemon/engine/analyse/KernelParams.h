// A kernel's parameters: which are buffers (size-annotated pointers), images, thread ids or values,
// and what each becomes in GLSL and in the ...Cmd signature. Reports the ones that cannot be bound.
#pragma once
#include "analyse/AnalysisContext.h"

namespace crossrt::engine {

// A kernel's Image2D reference parameter (by value it is an error the kernel's analysis reports).
bool IsImageParam(const ParmVarDecl* p);

void CheckKernelParams(Context& c, const CXXMethodDecl* md, const FunctionDecl* def, Kernel& k);

}  // namespace crossrt::engine
