// Level 3 in composed code (paper 3.10): loops over leaves whose bodies call virtual intersection
// functions become traces of a ray tracing pipeline, with an intersection shader per leaf class and a
// hit and a miss shader per call. Takes the traversal's loops; gives Kernel::leaves and the shaders.
#pragma once
#include "analyse/AnalysisContext.h"

namespace crossrt::engine {

// Virtual functions, level 3, in composed code. When every virtual call of the composed traversal
// `printer` printed for kernel `k` is a leaf call the hardware can run (TraceLeafCall), the kernel
// gets a ray generation variant whose traversal traces a ray where each leaves' loop was, with an
// intersection shader per class of leaf. Otherwise the reason goes to k.whyNoLeafShaders and the
// kernel keeps the switch.
void AnalyzeLeafTraversal(ASTContext& ctx, Reporter& rep, ClassModel& model, Kernel& k, const Composition& comp, const CXXRecordDecl* implClass,
                          const std::string& holderPrefix, const KernelPrinter& printer);

}  // namespace crossrt::engine
