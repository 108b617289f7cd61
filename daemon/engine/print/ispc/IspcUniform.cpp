// ISPC uniformity: which values of a kernel every lane of a gang shares. The printer declares a
// loop variable `uniform` when its start, bound and step are shared (a kernel's scalar parameters,
// members, the outer loops of a 2D or 3D nest, constants) and nothing else changes it: the loop
// then runs once per gang, and what it indexes with the variable (m_weights[k + m_radius]) is one
// load for all lanes instead of a gather, and a shared value. Part of IspcPrinter (IspcPrinter.h).
#include "analyse/AstQueries.h"
#include "print/ispc/IspcPrinter.h"
#include "print/PrinterParts.h"
#include "print/GlslTypes.h"
#include "analyse/WriteVisitor.h"

using namespace clang;

namespace crossrt::engine {

bool IspcPrinter::Uniform(const clang::Expr* e) const {
  e = e->IgnoreParenImpCasts();
  if (isa<IntegerLiteral, FloatingLiteral, CXXBoolLiteralExpr, CharacterLiteral>(e)) return true;
  if (auto* c = dyn_cast<CStyleCastExpr>(e)) return c->getType()->isArithmeticType() && Uniform(c->getSubExpr());
  if (auto* c = dyn_cast<CXXFunctionalCastExpr>(e)) return c->getType()->isArithmeticType() && Uniform(c->getSubExpr());
  if (auto* dr = dyn_cast<DeclRefExpr>(e)) {
    if (uniformValues.count(dr->getDecl())) return true;
    auto* vd = dyn_cast<VarDecl>(dr->getDecl());  // a constant (constexpr, or const with a constant initialiser)
    return vd && vd->getType().isConstQualified() && vd->getType()->isArithmeticType() && vd->getInit() &&
           vd->getInit()->isEvaluatable(m_ctx);
  }
  if (auto* me = dyn_cast<MemberExpr>(e)) {  // a scalar data member: self->m_x
    auto* f = dyn_cast<FieldDecl>(me->getMemberDecl());
    return f && isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts()) && f->getType()->isArithmeticType() && composedPrefix.empty() && !selfClass &&
           !m_structSelf;  // in a plain struct's method, `this` is the struct (a varying value), not the class
  }
  if (auto* mc = dyn_cast<CXXMemberCallExpr>(e)) {  // a member vector's size() (self->m_v_size), an image's width() or height()
    const CXXMethodDecl* method = mc->getMethodDecl();
    if (!method || !composedPrefix.empty() || selfClass || m_structSelf) return false;
    const clang::Expr* object = mc->getImplicitObjectArgument();
    if (method->getName() == "width" || method->getName() == "height") return IsImage2D(object->getType().getNonReferenceType());
    auto* f = ThisMemberField(object);
    return f && method->getName() == "size" && IsStdVector(f->getType());
  }
  if (auto* op = dyn_cast<CXXOperatorCallExpr>(e); op && op->getOperator() == OO_Subscript && op->getNumArgs() == 2) {
    // an element of a member vector at a shared index (self->m_v[k]: one load for the gang)
    if (!composedPrefix.empty() || selfClass || m_structSelf || !op->getType()->isArithmeticType()) return false;
    auto* f = ThisMemberField(op->getArg(0));
    return f && IsStdVector(f->getType()) && Uniform(op->getArg(1));
  }
  if (auto* uo = dyn_cast<UnaryOperator>(e))
    return (uo->getOpcode() == UO_Minus || uo->getOpcode() == UO_Plus || uo->getOpcode() == UO_Not || uo->getOpcode() == UO_LNot) &&
           Uniform(uo->getSubExpr());
  if (auto* bo = dyn_cast<BinaryOperator>(e))
    return !bo->isAssignmentOp() && bo->getOpcode() != BO_Comma && Uniform(bo->getLHS()) && Uniform(bo->getRHS());
  if (auto* co = dyn_cast<ConditionalOperator>(e))
    return Uniform(co->getCond()) && Uniform(co->getTrueExpr()) && Uniform(co->getFalseExpr());
  return false;
}

const VarDecl* IspcPrinter::UniformLoop(const ForStmt* fs) const {
  // for (int k = start; k < bound; ++k) with start and bound shared,
  auto* ds = dyn_cast_or_null<DeclStmt>(fs->getInit());
  auto* v = ds && ds->isSingleDecl() ? dyn_cast<VarDecl>(ds->getSingleDecl()) : nullptr;
  if (!v || !v->getType()->isIntegerType() || !v->getInit() || !Uniform(v->getInit())) return nullptr;
  auto* cond = dyn_cast_or_null<BinaryOperator>(fs->getCond() ? fs->getCond()->IgnoreParenImpCasts() : nullptr);
  if (!cond || !cond->isComparisonOp()) return nullptr;
  const bool lhsIsVar = NamedVar(cond->getLHS()) == v, rhsIsVar = NamedVar(cond->getRHS()) == v;
  if (!(lhsIsVar ? Uniform(cond->getRHS()) : rhsIsVar && Uniform(cond->getLHS()))) return nullptr;
  // a step of ++k, k++, --k, k--, k += shared or k -= shared,
  const clang::Expr* inc = fs->getInc() ? fs->getInc()->IgnoreParenImpCasts() : nullptr;
  bool step = false;
  if (auto* uo = dyn_cast_or_null<UnaryOperator>(inc)) step = uo->isIncrementDecrementOp() && NamedVar(uo->getSubExpr()) == v;
  if (auto* ca = dyn_cast_or_null<CompoundAssignOperator>(inc))
    step = (ca->getOpcode() == BO_AddAssign || ca->getOpcode() == BO_SubAssign) && NamedVar(ca->getLHS()) == v && Uniform(ca->getRHS());
  if (!step) return nullptr;
  // and a body that neither changes k nor leaves the loop early in some lanes only.
  struct Body : WriteVisitor<Body> {
    const VarDecl* v;
    bool bad = false;
    void Written(const clang::Expr* target, SourceLocation) { bad |= WrittenVar(target) == v; }
    bool VisitUnaryOperator(UnaryOperator* uo) {
      if (uo->getOpcode() == UO_AddrOf) bad |= WrittenVar(uo->getSubExpr()) == v;
      return WriteVisitor<Body>::VisitUnaryOperator(uo);
    }
    bool VisitBreakStmt(BreakStmt*) { return !(bad = true); }
    bool VisitContinueStmt(ContinueStmt*) { return !(bad = true); }
    bool VisitReturnStmt(ReturnStmt*) { return !(bad = true); }
    bool VisitGotoStmt(GotoStmt*) { return !(bad = true); }
  } body;
  body.v = v;
  body.TraverseStmt(const_cast<clang::Stmt*>(fs->getBody()));
  return body.bad ? nullptr : v;
}

}  // namespace crossrt::engine
