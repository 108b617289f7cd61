// `std::swap(m_a, m_b)` or `m_a.swap(m_b)` of two std::vector members in a control function, the
// ping-pong of iterative solvers. The host's vectors swap as written; on Vulkan the ...Cmd swaps
// their device buffers too (no copy: the kernels recorded after it bind them swapped) and records
// an update of the sizes the kernels see. Both vectors are read back after the call, since either
// may now hold what the kernels wrote. Takes a call in a control function's body; gives the ...Cmd's
// text after it and Control::vectorsWritten.
#include "control/ControlFunctions.h"
#include "control/ControlRewriter.h"
#include "generate/GeneratedNames.h"

using namespace clang;

namespace crossrt::engine {

bool ControlRewriter::TrySwap(const CallExpr* call) {
  const Expr *first = nullptr, *second = nullptr;
  if (auto* mc = dyn_cast<CXXMemberCallExpr>(call); mc && mc->getMethodDecl() && mc->getMethodDecl()->getName() == "swap" && mc->getNumArgs() == 1)
    first = mc->getImplicitObjectArgument(), second = mc->getArg(0);
  else if (auto* fd = call->getDirectCallee(); fd && fd->isInStdNamespace() && fd->getName() == "swap" && call->getNumArgs() == 2)
    first = call->getArg(0), second = call->getArg(1);
  if (!first) return false;
  const FieldDecl* a = ThisField(first);
  const FieldDecl* b = ThisField(second);
  if (!a || !b || !IsStdVector(a->getType().getNonReferenceType()) || !IsStdVector(b->getType().getNonReferenceType())) return false;
  Member* ma = FindMember(m_c.model, a->getNameAsString());
  Member* mb = FindMember(m_c.model, b->getNameAsString());
  if (!ma || !mb || ma->kind != MemberKind::Vector || mb->kind != MemberKind::Vector) return false;
  if (ma->appendedByKernels || mb->appendedByKernels) {
    m_c.rep.RecordingError(call->getBeginLoc(), "control function '" + m_ctrl.name + "' swaps '" + ma->name + "' and '" + mb->name +
                               "', and kernels append to one of them: its size is known only on the GPU while the call records",
                           "swap them after the call, or copy with a kernel");
    return true;
  }
  // Both get device buffers, and both are read back after the call.
  ma->usedByKernels = mb->usedByKernels = true;
  for (const Member* m : {ma, mb})
    if (std::find(m_ctrl.vectorsWritten.begin(), m_ctrl.vectorsWritten.end(), m->name) == m_ctrl.vectorsWritten.end())
      m_ctrl.vectorsWritten.push_back(m->name);
  auto& sm = m_c.ctx.getSourceManager();
  const SourceLocation end = Lexer::findLocationAfterToken(call->getEndLoc(), tok::semi, sm, m_c.ctx.getLangOpts(), false);
  if (end.isInvalid()) {
    m_c.rep.RecordingError(call->getBeginLoc(), "a swap of std::vector members inside an expression of control function '" + m_ctrl.name + "'",
                           "swap them in a statement of its own: '" + ma->name + ".swap(" + mb->name + ");'");
    return true;
  }
  const std::string buffers = generated::kVectorCopies + ".";
  m_gpu.InsertTextAfter(end, " std::swap(" + buffers + ma->name + ", " + buffers + mb->name + "); std::swap(" + buffers + ma->name + "Size, " + buffers +
                                 mb->name + "Size); crt_UpdateVectorSizeCmd(crt_cmd, offsetof(ClassData, " + generated::SizeField(ma->name) + "), " + ma->hostExpr +
                                 "); crt_UpdateVectorSizeCmd(crt_cmd, offsetof(ClassData, " + generated::SizeField(mb->name) + "), " + mb->hostExpr + ");");
  m_ctrl.swapsVectors = true;
  return true;
}

}  // namespace crossrt::engine
