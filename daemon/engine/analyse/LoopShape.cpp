// The shape of a kernel's loop nest: one parser of `for (int i = begin; i < end; ++i)` headers
// (ParseLoop, quiet or reporting), their thread counts, and what may stand before and after the nest.
#include "analyse/LoopShape.h"

#include "analyse/AnalysisContext.h"
#include "analyse/AstQueries.h"
#include "analyse/WriteVisitor.h"

#include <algorithm>

using namespace clang;

namespace crossrt::engine {

std::string LoopShapeProblem(ASTContext& ctx, const ForStmt* fs, LoopHeader& h) {
  auto* ds = dyn_cast_or_null<DeclStmt>(fs->getInit());
  if (!ds || !ds->isSingleDecl()) return "it must declare one loop variable";
  h.var = dyn_cast<VarDecl>(ds->getSingleDecl());
  if (!h.var || !h.var->getInit() || !h.var->getType()->isIntegerType()) return "the loop variable must be an initialised integer";
  h.start = h.var->getInit();
  auto* cond = dyn_cast_or_null<BinaryOperator>(fs->getCond() ? fs->getCond()->IgnoreImplicit() : nullptr);
  if (!cond || (cond->getOpcode() != BO_LT && cond->getOpcode() != BO_LE)) return "the condition must be 'i < end' or 'i <= end'";
  auto* lhs = dyn_cast<DeclRefExpr>(cond->getLHS()->IgnoreParenImpCasts());
  if (!lhs || lhs->getDecl() != h.var) return "the condition must compare the loop variable";
  h.end = cond->getRHS();
  h.inclusive = cond->getOpcode() == BO_LE;
  const Expr* inc = fs->getInc() ? fs->getInc()->IgnoreImplicit() : nullptr;
  bool stepOne = false;
  if (auto* uo = dyn_cast_or_null<UnaryOperator>(inc)) stepOne = uo->isIncrementOp() && NamedVar(uo->getSubExpr()) == h.var;
  if (auto* ca = dyn_cast_or_null<CompoundAssignOperator>(inc)) {
    Expr::EvalResult r;
    stepOne = ca->getOpcode() == BO_AddAssign && NamedVar(ca->getLHS()) == h.var && ca->getRHS()->EvaluateAsInt(r, ctx) && r.Val.getInt() == 1;
  }
  if (!stepOne) return "the step must be ++i, i++ or i += 1";
  return "";
}

const ForStmt* KernelLoopNest(ASTContext& ctx, const CompoundStmt* body) {
  const ForStmt* first = nullptr;
  for (auto* s : body->body()) {
    auto* fs = dyn_cast<ForStmt>(s);
    if (!fs) continue;
    if (!first) first = fs;
    auto* cond = dyn_cast_or_null<BinaryOperator>(fs->getCond() ? fs->getCond()->IgnoreImplicit() : nullptr);
    if (!cond || cond->getRHS()->isValueDependent() || !cond->getRHS()->isIntegerConstantExpr(ctx)) return fs;
  }
  return first;
}

bool ParseLoop(Context& c, const ForStmt* fs, LoopHeader& h, const std::string& kernel) {
  const std::string problem = LoopShapeProblem(c.ctx, fs, h);
  if (problem.empty()) return true;
  c.rep.Error(fs->getBeginLoc(), "loop of kernel '" + kernel + "' is not a parallel loop: " + problem,
              "write it as 'for (int i = start; i < end; i++)'; each iteration becomes one thread");
  return false;
}

std::string AsOperand(const std::string& expr) {
  std::string bare = expr;
  for (const char* token : {"->", "::"})
    for (size_t at; (at = bare.find(token)) != std::string::npos;) bare.erase(at, 2);
  return bare.find_first_of("+-*/%<>=!&|^?, ") == std::string::npos ? expr : "(" + expr + ")";
}

std::string CountExpr(Context& c, const LoopHeader& h) {
  std::string end = c.Text(h.end->getSourceRange()), start = c.Text(h.start->getSourceRange());
  Expr::EvalResult r;
  bool zeroStart = h.start->EvaluateAsInt(r, c.ctx) && r.Val.getInt() == 0;
  std::string count = zeroStart ? AsOperand(end) : AsOperand(end) + " - " + AsOperand(start);
  return h.inclusive ? count + " + 1" : count;
}

ChunkedLoop ChunkLoop(Rewriter& rw, ASTContext& ctx, const ForStmt* fs, const LoopHeader& h, const std::string& parallel, const std::string& grain) {
  const std::string type = h.var->getType().getUnqualifiedType().getAsString(ctx.getPrintingPolicy());
  const std::string begin = rw.getRewrittenText(h.start->getSourceRange()), end = rw.getRewrittenText(h.end->getSourceRange());
  rw.ReplaceText(h.start->getSourceRange(), "crt_first");
  rw.ReplaceText(fs->getCond()->getSourceRange(), h.var->getNameAsString() + " < crt_last");
  return {"crossrt::ParallelFor<" + type + ">(" + parallel + ", " + begin + ", " + (h.inclusive ? AsOperand(end) + " + 1" : end) + ", " + grain + ", [&](" +
              type + " crt_first, " + type + " crt_last) {",
          "});"};
}

namespace {

// The locals a statement declares (a loop's variable, a block's temporaries): its own to set.
struct DeclaredWithin : RecursiveASTVisitor<DeclaredWithin> {
  std::set<const VarDecl*> vars;
  bool VisitVarDecl(VarDecl* vd) { vars.insert(vd); return true; }
};

// What a statement sets: the locals of `locals` (or its own), or anything else: a member, a
// parameter, a reduced local, an object through a non-const call.
struct SetsWhat : WriteVisitor<SetsWhat> {
  const std::set<const VarDecl*>& locals;
  std::set<const VarDecl*> own;
  bool setsLocal = false, setsOther = false;
  explicit SetsWhat(const std::set<const VarDecl*>& l) : locals(l) {}
  void Written(const Expr* target, SourceLocation) {
    auto* vd = WrittenVar(target);
    if (vd && own.count(vd)) return;
    (vd && locals.count(vd) ? setsLocal : setsOther) = true;
  }
  bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
    if (auto* m = call->getMethodDecl(); m && !m->isConst()) Written(call->getImplicitObjectArgument(), call->getExprLoc());
    return true;
  }
  bool VisitCallExpr(CallExpr* call) {
    if (isa<CXXMemberCallExpr>(call) || isa<CXXOperatorCallExpr>(call)) return true;
    auto* fd = call->getDirectCallee();
    if (!fd) { setsOther = true; return true; }
    // A free function writes what it takes by non-const reference or pointer.
    for (unsigned i = 0; i < std::min(fd->getNumParams(), call->getNumArgs()); ++i) {
      QualType t = fd->getParamDecl(i)->getType();
      const bool byRef = t->isReferenceType() && !t.getNonReferenceType().isConstQualified();
      const bool byPtr = t->isPointerType() && !t->getPointeeType().isConstQualified();
      const Expr* arg = call->getArg(i)->IgnoreParenImpCasts();
      if (auto* uo = dyn_cast<UnaryOperator>(arg); byPtr && uo && uo->getOpcode() == UO_AddrOf) arg = uo->getSubExpr();
      if (byRef || byPtr) Written(arg, call->getExprLoc());
    }
    return true;
  }
  bool VisitCXXNewExpr(CXXNewExpr*) { setsOther = true; return true; }
  bool VisitCXXDeleteExpr(CXXDeleteExpr*) { setsOther = true; return true; }
  bool VisitCXXThrowExpr(CXXThrowExpr*) { setsOther = true; return true; }
};

}  // namespace

std::set<const Stmt*> StatementsSettingLocals(const std::vector<const Stmt*>& before, const std::set<const VarDecl*>& reduced) {
  std::set<const VarDecl*> locals;
  std::set<const Stmt*> out;
  for (auto* s : before) {
    if (auto* ds = dyn_cast<DeclStmt>(s)) {
      for (auto* d : ds->decls())
        if (auto* vd = dyn_cast<VarDecl>(d); vd && !reduced.count(vd)) locals.insert(vd);
      continue;
    }
    DeclaredWithin within;
    within.TraverseStmt(const_cast<Stmt*>(s));
    SetsWhat sets(locals);
    sets.own = within.vars;
    sets.TraverseStmt(const_cast<Stmt*>(s));
    if (sets.setsLocal && !sets.setsOther) out.insert(s);
  }
  return out;
}

bool CheckLoopEnds(Context& c, const std::string& kernel, const std::vector<const Stmt*>& before,
                   const std::vector<const Stmt*>& after, const Stmt* threadBody, const std::set<const Expr*>& reductionTargets,
                   const std::set<const Stmt*>& settingLocals) {
  std::set<const VarDecl*> locals;
  for (auto* s : before)
    if (auto* ds = dyn_cast<DeclStmt>(s))
      for (auto* d : ds->decls())
        if (auto* vd = dyn_cast<VarDecl>(d)) locals.insert(vd);
  struct LocalWrites : WriteVisitor<LocalWrites> {
    const std::set<const VarDecl*>& locals;
    std::vector<std::pair<const VarDecl*, SourceLocation>> found;
    const std::set<const Expr*>* skip = nullptr;  // the targets of reductions
    explicit LocalWrites(const std::set<const VarDecl*>& l) : locals(l) {}
    void Written(const Expr* target, SourceLocation loc) {
      if (skip && skip->count(target)) return;
      if (auto* vd = WrittenVar(target); vd && locals.count(vd)) found.push_back({vd, loc});
    }
    bool VisitUnaryOperator(UnaryOperator* uo) {
      if (uo->getOpcode() == UO_AddrOf) Written(uo->getSubExpr(), uo->getExprLoc());
      return WriteVisitor<LocalWrites>::VisitUnaryOperator(uo);
    }
    bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {  // m.set_col(1, c)
      if (auto* m = call->getMethodDecl(); m && !m->isConst()) Written(call->getImplicitObjectArgument(), call->getExprLoc());
      return true;
    }
  };
  bool ok = true;
  for (auto* s : before) {
    if (isa<DeclStmt>(s) || settingLocals.count(s)) continue;
    LocalWrites w(locals);
    w.TraverseStmt(const_cast<Stmt*>(s));
    for (auto& [vd, loc] : w.found) {
      c.rep.Error(loc, "a statement before the loop nest of kernel '" + kernel + "' changes '" + vd->getNameAsString() +
                  "', which every thread of the nest computes for itself, and also has effects beyond the locals (a member, a parameter, a reduced local, a call)",
                  "split it: one statement that only sets '" + vd->getNameAsString() + "', and one for the rest");
      ok = false;
    }
  }
  LocalWrites inLoop(locals);
  inLoop.skip = &reductionTargets;
  inLoop.TraverseStmt(const_cast<Stmt*>(threadBody));
  for (auto& [vd, loc] : inLoop.found) {
    c.rep.Error(loc, "the loop of kernel '" + kernel + "' writes '" + vd->getNameAsString() + "', declared before the loop: every iteration (a thread) would write one variable",
                "declare it inside the loop, or reduce it (x += v, x -= v, x = std::min(x, v), x = std::max(x, v))");
    ok = false;
  }
  struct Returns : RecursiveASTVisitor<Returns> {
    std::vector<SourceLocation> found;
    bool VisitReturnStmt(ReturnStmt* r) { found.push_back(r->getReturnLoc()); return true; }
    bool TraverseLambdaExpr(LambdaExpr*) { return true; }
  };
  for (auto* s : before) {
    Returns r;
    r.TraverseStmt(const_cast<Stmt*>(s));
    for (auto loc : r.found) {
      c.rep.GpuError(loc, "'return' before the loop nest of kernel '" + kernel + "': on the GPU the nest's threads would run anyway",
                  "test the condition in the control function before calling the kernel, or inside the loop");
      ok = false;
    }
  }
  (void)after;  // a 'return' after the nest ends the statements after it on both
  return ok;
}

}  // namespace crossrt::engine
