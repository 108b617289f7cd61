// One visitor of writes: assignments, compound assignments, increments and decrements, built in or
// overloaded. Passes derive from it and decide in Written(target, loc) what each write means to them.
#pragma once
#include "analyse/AnalysisContext.h"

namespace crossrt::engine {

// Calls Derived::Written(target, loc) for every assignment, increment and overloaded assignment operator.
template <class Derived>
struct WriteVisitor : RecursiveASTVisitor<Derived> {
  bool VisitBinaryOperator(BinaryOperator* bo) {
    if (bo->isAssignmentOp()) Self().Written(bo->getLHS(), bo->getExprLoc());
    return true;
  }
  bool VisitUnaryOperator(UnaryOperator* uo) {
    if (uo->isIncrementDecrementOp()) Self().Written(uo->getSubExpr(), uo->getExprLoc());
    return true;
  }
  bool VisitCXXOperatorCallExpr(CXXOperatorCallExpr* op) {
    if (op->isAssignmentOp() || op->getOperator() == OO_PlusPlus || op->getOperator() == OO_MinusMinus) Self().Written(op->getArg(0), op->getExprLoc());
    return true;
  }
  // A call's arguments bound to non-const reference parameters (GLSL inout): written by the callee.
  // Passes that count them call this from their VisitCallExpr.
  void ReferenceArguments(const CallExpr* call) {
    const FunctionDecl* fd = call->getDirectCallee();
    for (unsigned i = 0; fd && i < call->getNumArgs() && i < fd->getNumParams(); ++i) {
      const QualType t = fd->getParamDecl(i)->getType();
      if (t->isLValueReferenceType() && !t.getNonReferenceType().isConstQualified()) Self().Written(call->getArg(i), call->getExprLoc());
    }
  }
  Derived& Self() { return static_cast<Derived&>(*this); }
};

}  // namespace crossrt::engine
