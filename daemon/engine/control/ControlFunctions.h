// Control functions: the non-kernel methods that call kernels. Their bodies are rewritten twice, into
// the Vulkan class's ...Cmd recording (kernel calls become dispatches) and into the CPU class's code.
// Takes a control function; adds a Control to the model.
#pragma once
#include "analyse/AnalysisContext.h"
#include "analyse/AstQueries.h"
#include "analyse/BlockKernels.h"
#include "analyse/Naming.h"

namespace crossrt::engine {

// kernel_slicer's per-thread function: a member function (not a kernel) that calls kernel_ functions
// with a parameter of its own as the thread id, `void Run(uint tid, ...) { float t; kernel_A(tid, &t); ... }`.
// A ...Block control function runs it in a thread loop; it is no control function itself.
bool IsPerThreadFunction(const CXXMethodDecl* md, const CXXRecordDecl* cls);

const Stmt* SingleStatement(const Stmt* s);

// A pointer parameter of a control function that has no size (on any declaration, nor on a ...Block
// function's per-thread sibling) and that the function hands to no member function and stores in no
// variable: only host code uses it (memcpy(out, m_v.data(), ...) after the kernels), so no kernel
// needs a copy of it, and a library call on it is no GPU work.
bool IsHostOnlyPointer(const ParmVarDecl* p, const CXXRecordDecl* cls);

// The pass: control function `md` into a Control of the model (its ...Cmd body and its CPU body).
void AnalyzeControl(Context& c, const CXXMethodDecl* md, const FunctionDecl* def);

struct KernelCallFinder : RecursiveASTVisitor<KernelCallFinder> {
  const CXXRecordDecl* cls;  // a call of its per-thread functions counts too (they call kernels)
  std::vector<const Expr*> calls;
  explicit KernelCallFinder(const CXXRecordDecl* c) : cls(c) {}
  bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
    auto* md = call->getMethodDecl();
    if (md && (IsKernelName(md->getName()) || IsBlockKernelName(md->getName()) || IsPerThreadFunction(md, cls)) &&
        isa<CXXThisExpr>(call->getImplicitObjectArgument()->IgnoreParenImpCasts()))
      calls.push_back(call);
    return true;
  }
  bool VisitCallExpr(CallExpr* call) {
    auto* fd = call->getDirectCallee();
    static const std::set<std::string> library = {"exclusive_scan", "inclusive_scan", "fill", "memcpy", "memmove", "sort"};
    // (memcpy from <string.h> is the C library's, outside std, as LibraryCalls.cpp takes it.)
    if (!fd || !(fd->isInStdNamespace() || IsSystemDecl(fd)) || !library.count(fd->getNameAsString()) || isa<CXXMemberCallExpr>(call)) return true;
    for (auto* arg : call->arguments())  // host memory no kernel sees: the call runs on the host
      if (auto* dr = dyn_cast<DeclRefExpr>(arg->IgnoreParenImpCasts()))
        if (auto* p = dyn_cast<ParmVarDecl>(dr->getDecl()); p && IsHostOnlyPointer(p, cls)) return true;
    for (auto* arg : call->arguments()) {
      const Expr* base = arg->IgnoreParenImpCasts();
      if (auto* bo = dyn_cast<BinaryOperator>(base)) base = bo->getLHS()->IgnoreParenImpCasts();
      auto* mc = dyn_cast<CXXMemberCallExpr>(base);
      auto* dr = dyn_cast<DeclRefExpr>(base);  // a sized pointer parameter: a device buffer of the call
      auto* param = dr ? dyn_cast<ParmVarDecl>(dr->getDecl()) : nullptr;
      if ((mc && ThisField(mc->getImplicitObjectArgument()) && IsStdVector(ThisField(mc->getImplicitObjectArgument())->getType())) ||
          (param && param->getType()->isPointerType() && isa<CXXMethodDecl>(param->getDeclContext()) &&
           !IsKernelName(cast<CXXMethodDecl>(param->getDeclContext())->getName()))) {
        calls.push_back(call);
        break;
      }
    }
    return true;
  }
};

}  // namespace crossrt::engine
