// Loops in kernels: a counted `for` (its header first, so that a backend can tell the body about its
// variable: ISPC's uniform loops) and a range-based `for` over a fixed-size array, a std::array or a
// member std::vector of the class, which GLSL and ISPC do not have, as a counted loop.
#include "print/KernelPrinter.h"

#include "analyse/AstQueries.h"
#include "generate/GeneratedNames.h"
#include "print/GlslTypes.h"
#include "print/PrinterParts.h"

using namespace clang;

namespace crossrt::engine {

std::string KernelPrinter::ForLoop(const ForStmt* fs, int indent) {
  const std::string pad(indent * 2, ' ');
  std::string init;
  if (auto* ds = dyn_cast_or_null<DeclStmt>(fs->getInit()); ds && !ds->isSingleDecl()) {
    // `for (int i = 0, j = n - 1; ...)`: one declaration with several variables.
    for (auto* d : ds->decls()) {
      auto* vd = cast<VarDecl>(d);
      std::string one = init.empty() ? Declare(vd->getType(), LocalName(vd), vd->getLocation()) : LocalName(vd);
      init += (init.empty() ? "" : ", ") + one + (vd->getInit() ? " = " + Expr(vd->getInit()) : "");
    }
  } else if (fs->getInit()) {
    init = Stmt(fs->getInit(), 0);
    while (!init.empty() && (init.back() == '\n' || init.back() == ';')) init.pop_back();
    init = LoopInit(fs, init);
  }
  const std::string head = pad + "for (" + init + "; " + Expr(fs->getCond()) + "; " + Expr(fs->getInc()) + ")\n";  // (before the body: LoopInit
  ++m_loopDepth;                                                                                                  // tells it the variable)
  const std::string body = Stmt(fs->getBody(), isa<CompoundStmt>(fs->getBody()) ? indent : indent + 1);
  --m_loopDepth;
  return head + body;
}

std::string KernelPrinter::RangeFor(const CXXForRangeStmt* rf, int indent) {
  const std::string pad(indent * 2, ' ');
  const clang::Expr* range = rf->getRangeInit();
  const VarDecl* var = rf->getLoopVariable();
  auto* array = dyn_cast<ConstantArrayType>(range->getType().getCanonicalType().getTypePtr());
  uint64_t stdArraySize = 0;
  const bool stdArray = IsStdArray(range->getType(), nullptr, &stdArraySize);
  // A member std::vector of the class: up to its size, which kernels read as they read size().
  auto* member = dyn_cast<MemberExpr>(range->IgnoreParenImpCasts());
  auto* field = member && isa<CXXThisExpr>(member->getBase()->IgnoreParenImpCasts()) ? dyn_cast<FieldDecl>(member->getMemberDecl()) : nullptr;
  QualType elementType;
  if (field && (!IsStdVector(field->getType(), &elementType) || PolymorphicPointee(elementType))) field = nullptr;  // objects: call through them by index
  if (!array && !stdArray && !field)
    return Fail(rf->getColonLoc(), "a range-based for over '" + range->getType().getAsString(m_ctx.getPrintingPolicy()) + "' in a kernel",
                "kernels may loop with ':' over arrays of fixed size and the class's std::vector members; index other ranges: "
                "for (uint32_t k = 0; k < v.size(); ++k)"), "";
  if (rf->getInit()) return Fail(rf->getBeginLoc(), "an init-statement in a range-based for in a kernel", "declare the variable before the loop"), "";
  const QualType t = var->getType();
  if (t->isReferenceType() && !t.getNonReferenceType().isConstQualified())
    return Fail(var->getLocation(), "a range-based for with a non-const reference in a kernel",
                "GLSL has no references: index the array, for (int k = 0; k < n; ++k) a[k] = ..."), "";
  if (range->HasSideEffects(m_ctx)) return Fail(range->getBeginLoc(), "a range-based for over an expression with side effects in a kernel", "loop over a variable"), "";
  // The counter is named by depth, so that nested loops have their own.
  const std::string k = "crt_k" + std::to_string(m_loopDepth);
  std::string n;
  if (array || stdArray)
    n = std::to_string(array ? array->getSize().getZExtValue() : stdArraySize);
  else {
    m_uses.memberVectors.insert(field);
    m_uses.sizeReads.emplace(field, rf->getColonLoc());
    n = SizeAsInt(MemberAccess(generated::SizeField(field->getNameAsString())));
  }
  const std::string element = pad + "  " + (t.getNonReferenceType().isConstQualified() ? "const " : "") + Declare(t, LocalName(var), var->getLocation()) +
                              " = " + Expr(range) + "[" + k + "];\n";
  ++m_loopDepth;
  const clang::Stmt* body = rf->getBody();
  std::string inner;
  if (auto* cs = dyn_cast<CompoundStmt>(body))
    for (auto* c : cs->body()) inner += Stmt(c, indent + 1);
  else
    inner = Stmt(body, indent + 1);
  --m_loopDepth;
  // The count is the same in every thread: a language whose threads run in lockstep may share the
  // counter unless the body may leave the loop early in some threads only.
  struct Exits : RecursiveASTVisitor<Exits> {
    bool found = false;
    bool VisitBreakStmt(BreakStmt*) { return !(found = true); }
    bool VisitContinueStmt(ContinueStmt*) { return !(found = true); }
    bool VisitReturnStmt(ReturnStmt*) { return !(found = true); }
    bool VisitGotoStmt(GotoStmt*) { return !(found = true); }
  } exits;
  exits.TraverseStmt(const_cast<clang::Stmt*>(body));
  const std::string counter = RangeCounter(exits.found);
  return pad + "for (" + counter + k + " = 0; " + k + " < " + n + "; ++" + k + ")  // for (" + var->getNameAsString() + " : " +
         TrimmedSourceText(m_ctx, range->getSourceRange()) + ")\n" + pad + "{\n" + element + inner + pad + "}\n";
}

}  // namespace crossrt::engine
