// kernel_slicer's block-expansion kernels (kernelBE1D_, usually a template over the block size):
// a loop over blocks whose body runs the block's threads in [[parallel]] loops, sharing the block's
// local arrays between them. The CPU class runs each block on a core of its own, its [[parallel]]
// loops in order by that core: the blocks are independent, so this is the original's result. The
// GPU and ISPC classes refuse them at the kernel. Takes the class; adds BlockKernels to the model.
#pragma once
#include "analyse/AnalysisContext.h"

namespace crossrt::engine {

// Whether a method of this name is a block-expansion kernel.
bool IsBlockKernelName(llvm::StringRef name);

// The pass, over the class's methods and member templates.
void AnalyzeBlockKernels(Context& c);

}  // namespace crossrt::engine
