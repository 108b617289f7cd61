// ISPC's double: where a kernel computes in double, and where C++'s double only promotes a float.
//
// On the GPU a kernel has no double (Vulkan refuses the type), and the double that C++ makes of
// `x * 0.5` for a float x stays float. ISPC has C's double, so a class that declares doubles (a
// member sum, a buffer of doubles, a local) runs in double as written. The promotions stay float as
// on the GPU, so that a float kernel does not slow down to double: only an expression whose double
// comes from something declared double computes in double. A literal in such an expression gets
// ISPC's `d` suffix (ISPC reads an unsuffixed 0.1 as a float), as does an int converted there.
// Part of IspcPrinter (IspcPrinter.h).
#include "print/ispc/IspcPrinter.h"

#include <clang/AST/ParentMapContext.h>

using namespace clang;

namespace crossrt::engine {

namespace {

bool IsDouble(QualType t) { return t->isSpecificBuiltinType(BuiltinType::Double); }

}  // namespace

// e (of type double) holds a value declared double: a double variable, member, element or call, or
// arithmetic on one; not a promoted float or int, and not a bare literal.
bool IspcPrinter::DeclaredDouble(const clang::Expr* e) const {
  e = e->IgnoreParens();
  if (!IsDouble(e->getType().getCanonicalType())) return false;
  if (isa<FloatingLiteral>(e)) return false;
  if (auto* cast = dyn_cast<ImplicitCastExpr>(e))  // a promotion of a float or an int is not declared double
    return cast->getCastKind() != CK_FloatingCast && cast->getCastKind() != CK_IntegralToFloating && DeclaredDouble(cast->getSubExpr());
  if (auto* bo = dyn_cast<BinaryOperator>(e)) return DeclaredDouble(bo->getLHS()) || DeclaredDouble(bo->getRHS());
  if (auto* uo = dyn_cast<UnaryOperator>(e)) return DeclaredDouble(uo->getSubExpr());
  if (auto* co = dyn_cast<ConditionalOperator>(e)) return DeclaredDouble(co->getTrueExpr()) || DeclaredDouble(co->getFalseExpr());
  if (auto* call = dyn_cast<CallExpr>(e)) {  // the user's function that returns double, or a library one given a double
    const FunctionDecl* callee = call->getDirectCallee();
    if (callee && callee->hasBody()) return true;
    for (const clang::Expr* arg : call->arguments())
      if (DeclaredDouble(arg->IgnoreParenImpCasts())) return true;
    return false;
  }
  return true;  // a double variable, member, element or field, or the user's own (double)x
}

// e (a literal, or an int converted to double) sits where C++ computes in double with something
// declared double: beside one in arithmetic or a comparison, or (itself or arithmetic on it) as the
// value of a double variable, member, parameter or return.
bool IspcPrinter::InDoubleContext(const clang::Expr* e) const {
  if (!IsDouble(e->getType().getCanonicalType())) return false;
  const clang::Expr* child = e;
  for (;;) {
    const auto parents = m_ctx.getParents(*child);
    if (parents.empty()) return false;
    if (auto* paren = parents[0].get<ParenExpr>()) { child = paren; continue; }
    if (auto* uo = parents[0].get<UnaryOperator>(); uo && (uo->getOpcode() == UO_Minus || uo->getOpcode() == UO_Plus)) { child = uo; continue; }
    if (parents[0].get<ImplicitCastExpr>()) return false;  // converted to the float (or int) it is used as
    if (auto* bo = parents[0].get<BinaryOperator>()) {
      const clang::Expr* other = bo->getLHS()->IgnoreParens() == child->IgnoreParens() ? bo->getRHS() : bo->getLHS();
      if (DeclaredDouble(other->IgnoreParenImpCasts()) || (bo->isAssignmentOp() && IsDouble(bo->getLHS()->getType().getCanonicalType())))
        return true;
      if (!bo->isAdditiveOp() && !bo->isMultiplicativeOp()) return false;
      child = bo;  // 1.0 / 3.0: double where its result goes
      continue;
    }
    if (auto* call = parents[0].get<CallExpr>()) {  // an argument: of the user's function, or beside a double
      const FunctionDecl* callee = call->getDirectCallee();
      if (callee && callee->hasBody()) return true;
      for (const clang::Expr* arg : call->arguments())
        if (arg->IgnoreParens() != child->IgnoreParens() && DeclaredDouble(arg->IgnoreParenImpCasts())) return true;
      return false;
    }
    if (auto* co = parents[0].get<ConditionalOperator>()) {
      if (co->getCond()->IgnoreParens() == child->IgnoreParens()) return false;
      child = co;
      continue;
    }
    return true;  // a double variable's value, a double argument or return value (a float one has a cast between)
  }
}

}  // namespace crossrt::engine
