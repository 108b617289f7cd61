// Pointers in kernels and helpers, for a language that has none (GLSL).
//
// A pointer is followed to what it points at: an element of an array (a buffer the kernel binds, a
// member vector's data(), or a local array) at an offset, or one variable. Then
//   *p, p[k], p->f        print as   array[offset + k], array[offset + k].f   or   variable, variable.f
//   T* row = a + y * w;   prints as  const uint row_offset = y * w;   (later uses read a[row_offset + x])
//   const I* m = m_objects[k].get();  (a member vector of polymorphic pointers) prints as
//                         const uint m = k;   whose virtual calls m->F(...) print as m_objects_F(m, ...)
//   helper(&x) / helper(p)          a helper that only reads and writes *p gets p as an inout value;
//                                   one that indexes p gets a copy per buffer, with the offset.
//   Particle& p = m_particles[i];   prints nothing but a comment; p.vel, p prints as m_particles[i].vel
//                                   (a reference is the lvalue it names, as long as that stays one).
#include "analyse/AstQueries.h"
#include "print/KernelPrinter.h"
#include "analyse/WriteVisitor.h"

#include <clang/AST/RecursiveASTVisitor.h>
#include <clang/Basic/SourceManager.h>
#include <clang/Lex/Lexer.h>

using namespace clang;

namespace crossrt::engine {

namespace {
bool IsZero(const clang::Expr* e, ASTContext& ctx) {
  clang::Expr::EvalResult r;
  return e->EvaluateAsInt(r, ctx) && r.Val.getInt() == 0;
}
}  // namespace

std::optional<KernelPrinter::PointerTarget> KernelPrinter::Pointer(const clang::Expr* e) {
  e = e->IgnoreParens();
  if (auto* ic = dyn_cast<ImplicitCastExpr>(e)) {
    if (ic->getCastKind() == CK_ArrayToPointerDecay) {  // an array used as a pointer to its first element
      const clang::Expr* array = ic->getSubExpr()->IgnoreParenImpCasts();
      PointerTarget t;
      t.array = Expr(ic->getSubExpr());
      auto* dr = dyn_cast<DeclRefExpr>(array);
      t.local = dr && isa<VarDecl>(dr->getDecl()) && cast<VarDecl>(dr->getDecl())->hasLocalStorage();
      return t;
    }
    return Pointer(ic->getSubExpr());
  }
  // p + k, k + p, p - k: further into the same array.
  if (auto* bo = dyn_cast<BinaryOperator>(e); bo && (bo->getOpcode() == BO_Add || bo->getOpcode() == BO_Sub) && bo->getType()->isPointerType()) {
    const bool pointerLeft = bo->getLHS()->getType()->isPointerType();
    auto t = Pointer(pointerLeft ? bo->getLHS() : bo->getRHS());
    if (!t) return std::nullopt;
    if (!t->value.empty()) {
      Fail(e->getBeginLoc(), "pointer arithmetic on the address of a single variable in a kernel", "index an array or a buffer instead");
      return std::nullopt;
    }
    const clang::Expr* step = pointerLeft ? bo->getRHS() : bo->getLHS();
    const std::string k = (bo->getOpcode() == BO_Sub ? "-" : "") + std::string("(") + Expr(step) + ")";
    t->offset = t->offset.empty() ? k : t->offset + " + " + k;
    return t;
  }
  if (auto* uo = dyn_cast<UnaryOperator>(e); uo && uo->getOpcode() == UO_AddrOf) {
    const clang::Expr* sub = uo->getSubExpr()->IgnoreParens();
    // &a[i]: the element i of the array a points into.
    if (auto* as = dyn_cast<ArraySubscriptExpr>(sub)) {
      auto t = Pointer(as->getBase());
      if (!t) return std::nullopt;
      if (t->value.empty()) {
        const std::string i = Expr(as->getIdx());
        t->offset = t->offset.empty() ? i : t->offset + " + " + i;
        return t;
      }
    }
    // &m_v[i]: an element of a member vector.
    if (auto* op = dyn_cast<CXXOperatorCallExpr>(sub); op && op->getOperator() == OO_Subscript && IsStdVector(op->getArg(0)->getType())) {
      PointerTarget t;
      t.array = Expr(op->getArg(0));
      t.offset = Expr(op->getArg(1));
      return t;
    }
    PointerTarget t;  // &x, &s.f: one variable
    t.value = Expr(sub);
    return t;
  }
  // m_v.data(): the start of a member vector.
  if (auto* mc = dyn_cast<CXXMemberCallExpr>(e); mc && mc->getMethodDecl() && mc->getMethodDecl()->getName() == "data" &&
                                                 IsStdVector(mc->getImplicitObjectArgument()->getType())) {
    PointerTarget t;
    t.array = Expr(mc->getImplicitObjectArgument());
    return t;
  }
  if (auto* dr = dyn_cast<DeclRefExpr>(e)) {
    const ValueDecl* d = dr->getDecl();
    if (auto it = m_pointers.find(d); it != m_pointers.end()) return it->second;
    if (m_objectLocals.count(d)) {  // p->field of an object: reported as what p may do
      Expr(dr);
      return std::nullopt;
    }
    PointerTarget t;
    if (valueParams.count(d)) {  // a local of a thread loop, one value per thread
      t.value = SafeName(d->getNameAsString());
      t.perThread = d->getNameAsString();
      return t;
    }
    if (isa<ParmVarDecl>(d) && d->getType()->isPointerType()) {  // a kernel's pointer parameter: a buffer
      t.array = SafeName(d->getNameAsString());
      return t;
    }
  }
  if (isa<CXXNewExpr>(e)) {  // reported as heap allocation
    Expr(e);
    return std::nullopt;
  }
  Fail(e->getBeginLoc(), "pointer '" + TextOf(e) + "' cannot be followed in a kernel",
       "point into a buffer (a kernel's pointer parameter, a member vector's data(), &v[i], + k) or at a variable (&x)");
  return std::nullopt;
}

std::string KernelPrinter::Pointee(const PointerTarget& t, const clang::Expr* index, SourceLocation loc) {
  if (!t.value.empty()) {
    if (index && !IsZero(index, m_ctx) && !t.perThread.empty())
      return Fail(loc, "'" + t.perThread + "' holds one value per thread (a local of the control function's thread loop), used here as a pointer",
                  "read and write it as *" + t.perThread + " or " + t.perThread + "->field");
    if (index && !IsZero(index, m_ctx))
      return Fail(loc, "a pointer to one variable indexed past it in a kernel", "index an array or a buffer instead");
    return t.value;
  }
  const std::string i = index ? Expr(index) : "";
  std::string at = t.offset.empty() ? (i.empty() ? "0" : i) : i.empty() || IsZero(index, m_ctx) ? t.offset : t.offset + " + " + i;
  return t.array + "[" + at + "]";
}

// A helper's parameter declared as a const array (`const float boxMin[3]`): an array parameter in
// GLSL (by value) and ISPC (by address, as in C), the caller's array passed whole.
bool KernelPrinter::IsArrayValueParam(const ParmVarDecl* p) const {
  return p->getType()->isPointerType() && p->getType()->getPointeeType().isConstQualified() && p->getOriginalType()->isConstantArrayType();
}

// A helper's pointer parameter is a value (GLSL inout) when the helper only follows it to one
// element: *p, p->f, p[0], or hands it on to a helper of the same kind.
bool KernelPrinter::PointerIsValueOnly(const FunctionDecl* fn, const ParmVarDecl* p) {
  struct Uses : RecursiveASTVisitor<Uses> {
    const ParmVarDecl* p; ASTContext& ctx; KernelPrinter& printer;
    unsigned all = 0, asValue = 0;
    Uses(const ParmVarDecl* pp, ASTContext& c, KernelPrinter& pr) : p(pp), ctx(c), printer(pr) {}
    bool Names(const clang::Expr* e) const {
      auto* dr = dyn_cast<DeclRefExpr>(e->IgnoreParenImpCasts());
      return dr && dr->getDecl() == p;
    }
    bool VisitDeclRefExpr(DeclRefExpr* dr) { all += dr->getDecl() == p; return true; }
    bool VisitUnaryOperator(UnaryOperator* uo) { asValue += uo->getOpcode() == UO_Deref && Names(uo->getSubExpr()); return true; }
    bool VisitMemberExpr(MemberExpr* me) { asValue += me->isArrow() && Names(me->getBase()); return true; }
    bool VisitArraySubscriptExpr(ArraySubscriptExpr* as) { asValue += Names(as->getBase()) && IsZero(as->getIdx(), ctx); return true; }
    bool VisitCallExpr(CallExpr* call) {
      auto* callee = call->getDirectCallee();
      const FunctionDecl* def = nullptr;
      if (!callee || !callee->hasBody(def) || !def) return true;
      for (unsigned i = 0; i < call->getNumArgs() && i < def->getNumParams(); ++i)
        if (Names(call->getArg(i)) && def->getParamDecl(i)->getType()->isPointerType() && def != p->getDeclContext() &&
            printer.PointerIsValueOnly(def, def->getParamDecl(i)))
          ++asValue;
      return true;
    }
  } uses(p, m_ctx, *this);
  uses.TraverseStmt(fn->getBody());
  return uses.all == uses.asValue;
}

// The arguments of a call to a helper: a pointer argument is the value it points at (inout), or,
// where the helper indexes the pointer, the offset into the buffer it points into, for a copy of the
// helper bound to that buffer (`bindings`: parameter index -> buffer).
std::vector<std::string> KernelPrinter::HelperArgs(const FunctionDecl* fd, const CallExpr* call, std::map<unsigned, std::string>& bindings) {
  const FunctionDecl* def = nullptr;
  if (!fd->hasBody(def) || !def) def = fd;
  std::vector<std::string> args;
  const unsigned first = isa<CXXOperatorCallExpr>(call) && isa<CXXMethodDecl>(fd) ? 1 : 0;  // the object of a member operator
  for (unsigned i = first; i < call->getNumArgs(); ++i) {
    const clang::Expr* arg = call->getArg(i);
    const unsigned pi = i - first;
    const ParmVarDecl* p = pi < def->getNumParams() ? def->getParamDecl(pi) : nullptr;
    if (!p || !p->getType()->isPointerType()) {
      if (p && p->getType()->isReferenceType() && !p->getType().getNonReferenceType().isConstQualified()) ReferenceArgument(p, arg);
      args.push_back(Expr(arg));
      continue;
    }
    auto t = Pointer(arg);
    if (!t) {
      args.push_back("/*error*/");
      continue;
    }
    // ISPC binds no reference to a buffer's element (one per lane, at different addresses): a helper
    // that writes through its pointer gets the buffer and the offset there.
    if (IsArrayValueParam(p)) {  // const float boxMin[3]: the caller's array, whole and by value
      auto* decay = dyn_cast<ImplicitCastExpr>(arg->IgnoreParens());
      while (decay && decay->getCastKind() == CK_NoOp)  // float* to const float*
        decay = dyn_cast<ImplicitCastExpr>(decay->getSubExpr()->IgnoreParens());
      auto* passed = decay && decay->getCastKind() == CK_ArrayToPointerDecay ? m_ctx.getAsConstantArrayType(decay->getSubExpr()->getType()) : nullptr;
      auto* declared = m_ctx.getAsConstantArrayType(p->getOriginalType());
      if (passed && declared && passed->getSize() == declared->getSize() &&
          m_ctx.hasSameUnqualifiedType(passed->getElementType(), declared->getElementType()))
        args.push_back(Expr(decay->getSubExpr()));
      else
        args.push_back(Fail(arg->getBeginLoc(), "'" + fd->getNameAsString() + "' takes parameter '" + p->getNameAsString() + "' as an array of " +
                            std::to_string(m_ctx.getAsConstantArrayType(p->getOriginalType())->getSize().getZExtValue()) +
                            ", but gets a pointer", "pass an array of that size (a local's, a struct's field or a member's)"));
      continue;
    }
    const bool passedBufferElement = PassesBuffers() && !t->array.empty() && !t->local && !p->getType()->getPointeeType().isConstQualified();
    if (PointerIsValueOnly(def, p) && !passedBufferElement) {
      args.push_back(Pointee(*t, nullptr, arg->getBeginLoc()));
      continue;
    }
    if (!t->value.empty() || t->local) {
      Fail(arg->getBeginLoc(), "'" + fd->getNameAsString() + "' indexes its pointer parameter '" + p->getNameAsString() +
           "', but gets the address of " + (t->local ? "a local array" : "one variable"),
           "pass a pointer into a buffer (a kernel's pointer parameter or a member vector's data()), or give the helper the element");
      args.push_back("/*error*/");
      continue;
    }
    bindings[pi] = t->array;
    if (PassesBuffers()) args.push_back(t->array);  // the buffer itself, then the offset into it
    args.push_back(t->offset.empty() ? "0u" : t->offset);
  }
  return args;
}

// `T* p = <pointer>;` in a kernel or helper: p follows what it was set to; an offset is fixed where
// p is set (later changes of its variables do not move p, as in C++).
std::string KernelPrinter::PointerLocal(const VarDecl* vd, const std::string& pad) {
  const clang::Expr* init = vd->getInit();
  if (!init) return Fail(vd->getLocation(), "pointer '" + vd->getNameAsString() + "' declared without a value in a kernel", "set it where it is declared"), "";
  struct Reassigned : RecursiveASTVisitor<Reassigned> {
    const VarDecl* vd; bool found = false;
    explicit Reassigned(const VarDecl* v) : vd(v) {}
    bool Names(const clang::Expr* e) const {
      auto* dr = dyn_cast<DeclRefExpr>(e->IgnoreParenImpCasts());
      return dr && dr->getDecl() == vd;
    }
    bool VisitBinaryOperator(BinaryOperator* bo) { found |= bo->isAssignmentOp() && Names(bo->getLHS()); return true; }
    bool VisitUnaryOperator(UnaryOperator* uo) { found |= uo->isIncrementDecrementOp() && Names(uo->getSubExpr()); return true; }
  } reassigned(vd);
  if (auto* fn = dyn_cast<FunctionDecl>(vd->getDeclContext()); fn && fn->getBody()) reassigned.TraverseStmt(fn->getBody());
  if (reassigned.found)
    return Fail(vd->getLocation(), "pointer '" + vd->getNameAsString() + "' is moved in a kernel", "keep an index next to the array and change that instead"), "";
  // An object of a member vector of polymorphic pointers: the element's index, through which the
  // virtual calls p->Method(...) reach the object's class (VirtualCall).
  const clang::Expr* objectIndex = nullptr;
  if (const FieldDecl* objects = ObjectLocal(vd, &objectIndex)) {
    m_objectLocals[vd] = objects;
    const std::string index = Expr(objectIndex);
    return pad + "const uint " + LocalName(vd) + " = " + ObjectLocalIndex(index) + ";  // " +
           vd->getNameAsString() + " points at " + objects->getNameAsString() + "[" + LocalName(vd) + "]\n";
  }
  auto t = Pointer(init);
  if (!t) {
    PointerTarget reported;  // reported once: its uses say nothing more
    reported.value = "/*error*/";
    m_pointers[vd] = reported;
    return "";
  }
  std::string out;
  if (!t->offset.empty()) {
    const std::string offset = LocalName(vd) + "_offset";
    out = pad + "const uint " + offset + " = " + t->offset + ";  // " + vd->getNameAsString() + " points to " + t->array + "[" + offset + "]\n";
    t->offset = offset;
  }
  m_pointers[vd] = *t;
  return out;
}

std::string KernelPrinter::TextOf(const clang::Expr* e) const {
  auto& sm = m_ctx.getSourceManager();
  return Lexer::getSourceText(CharSourceRange::getTokenRange(sm.getExpansionRange(e->getSourceRange()).getAsRange()), sm, m_ctx.getLangOpts()).str();
}

std::optional<std::string> KernelPrinter::ReferenceAlias(const VarDecl* vd, const DeclStmt* decl, std::string& why) {
  const clang::Expr* init = vd->getInit();
  if (!init) return why = "it has no initialiser", std::nullopt;
  init = init->IgnoreParenImpCasts();
  if (init->HasSideEffects(m_ctx, false)) return why = "what it refers to has side effects", std::nullopt;
  // An lvalue of variables, members, fields and elements: the variables its indices read.
  std::vector<const clang::Expr*> indices;
  for (const clang::Expr* e = init;;) {
    e = e->IgnoreParenImpCasts();
    if (auto* me = dyn_cast<MemberExpr>(e)) { e = me->getBase(); continue; }
    if (auto* sub = dyn_cast<ArraySubscriptExpr>(e)) { indices.push_back(sub->getIdx()); e = sub->getBase(); continue; }
    if (auto* op = dyn_cast<CXXOperatorCallExpr>(e); op && op->getOperator() == OO_Subscript && op->getNumArgs() == 2) {
      indices.push_back(op->getArg(1));
      e = op->getArg(0);
      continue;
    }
    if (isa<DeclRefExpr, CXXThisExpr>(e)) break;
    return why = "it refers to something other than a variable, member, field or element", std::nullopt;
  }
  struct Reads : RecursiveASTVisitor<Reads> {
    std::set<const VarDecl*> vars;
    bool VisitDeclRefExpr(DeclRefExpr* dr) {
      if (auto* v = dyn_cast<VarDecl>(dr->getDecl())) vars.insert(v);
      return true;
    }
  } reads;
  for (const clang::Expr* index : indices) reads.TraverseStmt(const_cast<clang::Expr*>(index));
  // Written after the declaration, in the statements of its block that follow it?
  struct Writes : WriteVisitor<Writes> {
    const std::set<const VarDecl*>* vars;
    const VarDecl* written = nullptr;
    void Written(const clang::Expr* target, SourceLocation) {
      if (const VarDecl* v = WrittenVar(target); v && vars->count(v) && !written) written = v;
    }
  } writes;
  writes.vars = &reads.vars;
  auto parents = m_ctx.getParents(*decl);
  const auto* block = parents.empty() ? nullptr : parents[0].get<CompoundStmt>();
  if (!block) return why = "it is not declared in a block", std::nullopt;
  bool after = false;
  for (const clang::Stmt* s : block->body()) {
    if (after) writes.TraverseStmt(const_cast<clang::Stmt*>(s));
    after = after || s == decl;
  }
  if (writes.written) return why = "'" + writes.written->getNameAsString() + "', which picks what it refers to, changes after it", std::nullopt;
  return Expr(init);
}

}  // namespace crossrt::engine
