// Host code of a control function that uses what kernels write on the GPU: members they write,
// and output pointer parameters. The Vulkan class records the whole body before any of it runs, so
// such a use, done while recording, would see the value from before the call. After the last
// statement that records GPU work the uses are sound once deferred: the ...Cmd stores those
// statements (the host tail, `m_mean = m_sum / float(n);`) as a lambda, capturing the locals they
// read, and the generated control function runs it after the kernels' results are back. Between
// kernels such uses are an error. Takes a control function's body; gives Control::hasHostTail and
// the ...Cmd's lambda.
#include "ControlFunctions.h"
#include "ControlRewriter.h"

using namespace clang;

namespace crossrt::engine {

namespace {

// What host code in `s` reads of the GPU's results: plain members of the class data that kernels
// write (every mention but the left side of a plain assignment, `m_x = ...`, which only writes
// it), and the control function's output pointer parameters (non-const: copied back after the
// call), any use but handing one to a kernel or a library call on device data. As (where, name).
std::vector<std::pair<const Expr*, std::string>> KernelWrittenReads(Context& c, const FunctionDecl* control, const Stmt* s) {
  struct Finder : RecursiveASTVisitor<Finder> {
    Context& c;
    const FunctionDecl* control;
    std::set<const MemberExpr*> assigned;
    std::set<const DeclRefExpr*> handedOver;  // output parameters passed to kernels and library calls
    std::vector<std::pair<const Expr*, std::string>> reads;
    Finder(Context& cc, const FunctionDecl* ctrl) : c(cc), control(ctrl) {}
    void Assigned(const Expr* lhs) {
      if (auto* me = dyn_cast<MemberExpr>(lhs->IgnoreParenImpCasts())) assigned.insert(me);
    }
    void HandedOver(const Expr* arg) {
      arg = arg->IgnoreParenImpCasts();
      if (auto* bo = dyn_cast<BinaryOperator>(arg); bo && bo->isAdditiveOp()) arg = bo->getLHS()->IgnoreParenImpCasts();  // out + k
      if (auto* dr = dyn_cast<DeclRefExpr>(arg)) handedOver.insert(dr);
    }
    bool VisitBinaryOperator(BinaryOperator* bo) {  // visited before its operands
      if (bo->getOpcode() == BO_Assign) Assigned(bo->getLHS());
      return true;
    }
    bool VisitCXXOperatorCallExpr(CXXOperatorCallExpr* op) {
      if (op->getOperator() == OO_Equal) Assigned(op->getArg(0));
      return true;
    }
    bool VisitMemberExpr(MemberExpr* me) {
      if (assigned.count(me) || !isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts())) return true;
      auto* f = dyn_cast<FieldDecl>(me->getMemberDecl());
      const Member* m = f ? FindMember(c.model, f->getNameAsString()) : nullptr;
      if (m && m->kind == MemberKind::Plain && m->inClassData && m->writtenByKernels) reads.push_back({me, f->getNameAsString()});
      return true;
    }
    bool VisitDeclRefExpr(DeclRefExpr* dr) {
      auto* p = dyn_cast<ParmVarDecl>(dr->getDecl());
      if (!p || p->getDeclContext() != control || handedOver.count(dr)) return true;
      const QualType t = p->getType();
      if (t->isPointerType() && !t->getPointeeType().isConstQualified()) reads.push_back({dr, p->getNameAsString()});
      return true;
    }
  } finder(c, control);
  KernelCallFinder gpu(c.cls);  // the kernel and library calls of `s`, whose arguments are handed over
  gpu.TraverseStmt(const_cast<Stmt*>(s));
  for (const Expr* call : gpu.calls)
    for (const Expr* arg : cast<CallExpr>(call)->arguments()) finder.HandedOver(arg);
  finder.TraverseStmt(const_cast<Stmt*>(s));
  return finder.reads;
}

// Where `s` first records GPU work: a kernel call (or a per-thread function's), a library call on
// device data, LiteMath's ReduceAddInit, or clear() of a vector kernels append to. Invalid if none.
SourceLocation FirstGpuWork(Context& c, const Stmt* s) {
  KernelCallFinder kernels(c.cls);
  kernels.TraverseStmt(const_cast<Stmt*>(s));
  SourceLocation first = kernels.calls.empty() ? SourceLocation() : kernels.calls.front()->getBeginLoc();
  struct Others : RecursiveASTVisitor<Others> {
    Context& c;
    SourceLocation at;
    explicit Others(Context& cc) : c(cc) {}
    bool VisitCallExpr(CallExpr* call) {
      auto* fd = call->getDirectCallee();
      bool gpu = fd && fd->getName() == "ReduceAddInit";
      if (auto* mc = dyn_cast<CXXMemberCallExpr>(call); mc && mc->getMethodDecl() && mc->getMethodDecl()->getName() == "clear")
        if (auto* f = ThisField(mc->getImplicitObjectArgument())) gpu = gpu || c.appended.count(f->getNameAsString());
      if (gpu && at.isInvalid()) at = call->getBeginLoc();
      return true;
    }
  } others(c);
  others.TraverseStmt(const_cast<Stmt*>(s));
  auto& sm = c.ctx.getSourceManager();
  if (first.isInvalid() || (others.at.isValid() && sm.isBeforeInTranslationUnit(others.at, first))) first = others.at;
  return first;
}

}  // namespace

void ControlRewriter::FindHostTail() {
  auto* body = dyn_cast<CompoundStmt>(m_def->getBody());
  if (!body) return;
  auto& sm = m_c.ctx.getSourceManager();
  const std::vector<const Stmt*> statements(body->body_begin(), body->body_end());
  int first = -1, last = -1;
  SourceLocation firstWork;
  for (int i = 0; i < int(statements.size()); ++i)
    if (SourceLocation at = FirstGpuWork(m_c, statements[i]); at.isValid()) {
      if (first < 0) firstWork = at, first = i;
      last = i;
    }
  if (last < 0) return;
  // Between the first GPU work and the last: a read after the first, or anywhere in a loop that
  // records GPU work (its next round reads what this one's kernels write).
  for (int i = first; i <= last; ++i) {
    const bool loop = isa<ForStmt, WhileStmt, DoStmt, CXXForRangeStmt>(statements[i]) && FirstGpuWork(m_c, statements[i]).isValid();
    for (const auto& [read, name] : KernelWrittenReads(m_c, m_def, statements[i])) {
      if (!loop && !sm.isBeforeInTranslationUnit(firstWork, read->getBeginLoc())) continue;
      m_c.rep.GpuError(read->getExprLoc(), "control function '" + m_ctrl.name + "' uses '" + name +
                       "' between kernel calls, but kernels write it on the GPU: the calls are recorded before any runs, so this sees its value from before the call",
                       "read it inside a kernel, which sees the GPU's copy, or after the last kernel call: code there runs once the results are back");
    }
  }
  // The tail moves only when it needs to: when it reads what the kernels wrote.
  bool reads = false;
  for (size_t i = size_t(last) + 1; i < statements.size(); ++i) reads = reads || !KernelWrittenReads(m_c, m_def, statements[i]).empty();
  if (!reads) return;
  m_tail.assign(statements.begin() + last + 1, statements.end());
}

void ControlRewriter::MoveHostTail() {
  if (m_tail.empty()) return;
  auto& sm = m_c.ctx.getSourceManager();
  SourceLocation end = Lexer::findLocationAfterToken(m_tail.back()->getEndLoc(), tok::semi, sm, m_c.ctx.getLangOpts(), false);
  if (end.isInvalid()) end = Lexer::getLocForEndOfToken(m_tail.back()->getEndLoc(), 0, sm, m_c.ctx.getLangOpts());  // a block or loop
  const CharSourceRange range = CharSourceRange::getCharRange(m_tail.front()->getBeginLoc(), end);
  // The variables of the body the tail reads, declared before it (parameters too): captured by copy.
  struct Uses : RecursiveASTVisitor<Uses> {
    const FunctionDecl* def;
    std::set<const Decl*> inside;
    std::vector<std::string> captured;
    bool VisitVarDecl(VarDecl* vd) { inside.insert(vd); return true; }
    bool VisitDeclRefExpr(DeclRefExpr* dr) {
      auto* vd = dyn_cast<VarDecl>(dr->getDecl());
      if (!vd || !vd->hasLocalStorage() || inside.count(vd) || vd->getDeclContext() != def) return true;
      if (std::find(captured.begin(), captured.end(), vd->getNameAsString()) == captured.end()) captured.push_back(vd->getNameAsString());
      return true;
    }
  } uses;
  uses.def = m_def;
  for (const Stmt* s : m_tail) uses.TraverseStmt(const_cast<Stmt*>(s));
  for (const auto& [vd, temporary] : m_temporaries)
    if (std::find(uses.captured.begin(), uses.captured.end(), vd->getNameAsString()) != uses.captured.end())
      m_c.rep.GpuError(vd->getLocation(), "the code of '" + m_ctrl.name + "' after its last kernel reads '" + vd->getNameAsString() +
                       "', whose elements are the GPU's", "make it a member, which the generated class copies back");
  std::string captures = "this";
  for (const std::string& name : uses.captured) captures += ", " + name;
  m_ctrl.hasHostTail = true;
  m_gpu.ReplaceText(range, "m_hostTail_" + m_ctrl.name + " = [" + captures + "]() mutable {\n" +
                               std::string(Lexer::getSourceText(range, sm, m_c.ctx.getLangOpts())) + "\n};");
}

}  // namespace crossrt::engine
