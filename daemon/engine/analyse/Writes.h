// What a kernel writes: member reductions (+=, min, max on members), appends, atomics, member writes
// and constant stores (WriteScanner), and reductions of locals declared before the loop nest
// (LocalReductionScanner). Takes a kernel's body; gives the writes each later pass must translate.
#pragma once
#include "analyse/AnalysisContext.h"
#include "analyse/AstQueries.h"
#include "analyse/LoopShape.h"

namespace crossrt::engine {

std::string Identity(ReduceOp op, const std::string& glslType);

// A statement's source text with its ';' (the AST range of an expression statement ends before it).
std::string StatementText(Context& c, const Stmt* s);

// Collects the reductions (m += x, m = min(m, x), ...) and member writes of a thread body.
struct WriteScanner : RecursiveASTVisitor<WriteScanner> {
  Context& c;
  std::map<const FieldDecl*, ReduceOp> reductions;
  std::set<const MemberExpr*> reductionUses;  // member references that belong to a reduction statement
  std::map<const FieldDecl*, SourceLocation> reductionSites;  // the first reduction of a member array's elements
  std::set<const FieldDecl*> vectorWrites;
  std::set<const FieldDecl*> atomicMembers;  // plain data members written by crossrt::Atomic*
  const FunctionDecl* helper = nullptr;  // scanning a helper's body: reductions are not allowed there
  // Scanning statements one thread runs (before or after a kernel's loop nest): members are written
  // as on the CPU, no race and no reduction.
  bool singleThread = false;
  std::set<const FieldDecl*> memberWrites;  // plain members written that way
  explicit WriteScanner(Context& ctx) : c(ctx) {}

  static const MemberExpr* AsThisMember(const Expr* e) {
    auto* me = dyn_cast<MemberExpr>(e->IgnoreParenImpCasts());
    return me && isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts()) ? me : nullptr;
  }
  void Write(const Expr* lhs, SourceLocation loc, std::optional<ReduceOp> op, const std::vector<const MemberExpr*>& uses) {
    const FieldDecl* root = RootField(lhs);
    if (!root) return;
    // A method of a plain struct the kernel holds (rng.Next() changing rng.state) writes that struct, not the class.
    if (auto* owner = dyn_cast<CXXRecordDecl>(root->getParent()); owner && c.cls && !IsClassOrBase(owner, c.cls)) return;
    if (IsStdVector(root->getType())) { vectorWrites.insert(root); return; }
    if (IsImage2D(root->getType())) {
      // m_img[p] = v and m_img.at(x, y) = v print as imageStore; a part of a texel cannot be stored.
      auto* op = dyn_cast<CXXOperatorCallExpr>(lhs->IgnoreParenImpCasts());
      if (!(op && op->getOperator() == OO_Subscript && ThisField(op->getArg(0)) == root))
        c.rep.GpuError(loc, "kernel writes part of a texel of Image2D member '" + root->getNameAsString() + "'",
                    "GPU images store whole texels: read the texel into a variable, change it, and write it back with " +
                    root->getNameAsString() + "[p] = value");
      return;
    }
    auto* direct = AsThisMember(lhs);
    if (singleThread) {
      memberWrites.insert(root);
      return;
    }
    if (ThroughPointer(lhs)) {  // m_out.summ[i] = ...: the memory a pointer member points at, not the member
      // The CPU class runs the kernel and its helpers as written, each thread at its index (as
      // through a kernel's pointer parameter); one constant element written from every thread stays
      // a data race.
      if (c.model.forCpu && !c.model.forIspc) {
        if (!IndexedPerThread(lhs, c.ctx))
          c.rep.Error(loc, std::string(helper ? "helper function '" + helper->getNameAsString() + "'" : "kernel") + " writes one element through pointer member '" + root->getNameAsString() + "' from every thread (a data race)",
                      "write at the thread's own index (p[i]), or accumulate in a member with 'm += x' (a reduction)");
        return;
      }
      c.rep.Error(loc, std::string(helper ? "helper function '" + helper->getNameAsString() + "'" : "kernel") + " writes through pointer member '" +
                           root->getNameAsString() + "' (kernel_slicer's setter form)",
                  c.model.forIspc ? "ISPC kernels reach memory through the class's buffers: pass the output as a size-annotated pointer parameter, "
                                    "or write to a std::vector member (the CPU backend runs this kernel as written)"
                                  : "GPU kernels reach memory through buffers: pass the output as a size-annotated pointer parameter, or write to "
                                    "a std::vector member (the CPU backend runs this kernel as written)");
      return;
    }
    if (helper) {
      c.rep.Error(loc, "helper function '" + helper->getNameAsString() + "' writes class member '" + root->getNameAsString() + "' (called from every thread: a data race)",
                  "accumulate in the kernel's loop body (m += x, min, max), or return the value from the helper");
      return;
    }
    if (auto* element = op && !direct ? ReducedElement(lhs, root) : nullptr) {  // coefs[2] += x, bins[b] += 1: elements of a member array
      auto [it, fresh] = reductions.emplace(root, *op);
      if (!fresh && it->second != *op)
        c.rep.Error(loc, "member '" + root->getNameAsString() + "' is reduced with two different operations in one kernel",
                    "use one of +=, -=, min or max per member");
      reductionUses.insert(element);
      for (auto* u : uses) reductionUses.insert(u);
      reductionSites.emplace(root, loc);
      return;
    }
    if (op && direct) {
      auto [it, fresh] = reductions.emplace(root, *op);
      if (!fresh && it->second != *op)
        c.rep.Error(loc, "member '" + root->getNameAsString() + "' is reduced with two different operations in one kernel",
                    "use one of +=, -=, min or max per member");
      for (auto* u : uses) reductionUses.insert(u);
      return;
    }
    c.rep.Error(loc, "kernel writes class member '" + root->getNameAsString() + "' from every thread (a data race)",
                "accumulate with 'm += x', 'm = std::min(m, x)' or 'm = std::max(m, x)' (a reduction), or write to an element of a std::vector member");
  }
  // `arr[k]` with arr the one-dimensional array member `root` (k a constant, or any index a thread
  // computes): arr's MemberExpr. Each thread reduces into an array of its own.
  const MemberExpr* ReducedElement(const Expr* lhs, const FieldDecl* root) const {
    auto* as = dyn_cast<ArraySubscriptExpr>(lhs->IgnoreParenImpCasts());
    auto* me = as ? AsThisMember(as->getBase()) : nullptr;
    if (!me || me->getMemberDecl() != root) return nullptr;
    auto* arr = dyn_cast<ConstantArrayType>(root->getType().getCanonicalType().getTypePtr());
    return arr && !isa<ArrayType>(arr->getElementType().getCanonicalType().getTypePtr()) ? me : nullptr;
  }
  // Whether the written lvalue is reached through a pointer (p[i], *p, p->f on the way to the member).
  static bool ThroughPointer(const Expr* e) {
    for (e = e->IgnoreParenImpCasts();; e = e->IgnoreParenImpCasts()) {
      if (auto* as = dyn_cast<ArraySubscriptExpr>(e)) {
        if (as->getBase()->IgnoreParenImpCasts()->getType()->isPointerType()) return true;
        e = as->getBase();
      } else if (auto* uo = dyn_cast<UnaryOperator>(e); uo && uo->getOpcode() == UO_Deref) {
        return true;
      } else if (auto* me = dyn_cast<MemberExpr>(e)) {
        if (me->isArrow() && !isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts())) return true;
        e = me->getBase();
      } else {
        return false;
      }
    }
  }
  // p[k] with an index that is not a constant, on the way to the written lvalue.
  static bool IndexedPerThread(const Expr* e, ASTContext& ctx) {
    for (e = e->IgnoreParenImpCasts();; e = e->IgnoreParenImpCasts()) {
      if (auto* as = dyn_cast<ArraySubscriptExpr>(e)) {
        Expr::EvalResult r;
        if (as->getBase()->IgnoreParenImpCasts()->getType()->isPointerType()) return !as->getIdx()->EvaluateAsInt(r, ctx);
        e = as->getBase();
      } else if (auto* me = dyn_cast<MemberExpr>(e)) {
        e = me->getBase();
      } else {
        return false;
      }
    }
  }
  std::optional<ReduceOp> MinMax(const Expr* lhs, const Expr* rhs, std::vector<const MemberExpr*>& uses) {
    auto* call = dyn_cast<CallExpr>(rhs->IgnoreImplicit());
    if (!call || !call->getDirectCallee() || call->getNumArgs() != 2) return std::nullopt;
    std::string n = call->getDirectCallee()->getNameAsString();
    bool isMin = n == "min" || n == "fmin" || n == "fminf", isMax = n == "max" || n == "fmax" || n == "fmaxf";
    if (!isMin && !isMax) return std::nullopt;
    auto* target = ThisField(lhs);
    for (auto* arg : call->arguments())
      if (auto* me = AsThisMember(arg); me && target && me->getMemberDecl() == target) {
        uses.push_back(me);
        return isMin ? ReduceOp::Min : ReduceOp::Max;
      }
    // m_lo[k] = std::min(m_lo[k], x): the same element of a member array on both sides.
    auto* element = dyn_cast<ArraySubscriptExpr>(lhs->IgnoreParenImpCasts());
    auto* array = element ? AsThisMember(element->getBase()) : nullptr;
    if (!array) return std::nullopt;
    llvm::FoldingSetNodeID written;
    element->Profile(written, c.ctx, true);
    for (auto* arg : call->arguments()) {
      auto* read = dyn_cast<ArraySubscriptExpr>(arg->IgnoreParenImpCasts());
      auto* me = read ? AsThisMember(read->getBase()) : nullptr;
      if (!me || me->getMemberDecl() != array->getMemberDecl()) continue;
      llvm::FoldingSetNodeID same;
      read->Profile(same, c.ctx, true);
      if (same != written) continue;
      uses.push_back(me);
      return isMin ? ReduceOp::Min : ReduceOp::Max;
    }
    return std::nullopt;
  }
  // `m = constant;` of a scalar member from the threads (kernel_slicer's flags: m_found = 1): every
  // thread that stores, stores the same value, so the result is that of the CPU. Stored
  // atomically on the CPU; the values of each member must agree, and no thread may read it.
  std::map<const FieldDecl*, std::set<std::string>> constantStores;
  std::vector<const BinaryOperator*> constantStoreExprs;
  std::set<const MemberExpr*> constantStoreUses;
  bool ConstantStore(BinaryOperator* bo) {
    auto* me = AsThisMember(bo->getLHS());
    auto* f = me ? dyn_cast<FieldDecl>(me->getMemberDecl()) : nullptr;
    Expr::EvalResult r;
    if (!f || bo->getOpcode() != BO_Assign || singleThread || helper || !f->getType()->isScalarType() || f->getType()->isPointerType() ||
        !bo->getRHS()->EvaluateAsRValue(r, c.ctx))
      return false;
    constantStores[f].insert(r.Val.getAsString(c.ctx, bo->getRHS()->getType()));
    constantStoreExprs.push_back(bo);
    constantStoreUses.insert(me);
    return true;
  }
  bool VisitBinaryOperator(BinaryOperator* bo) {
    if (!bo->isAssignmentOp() || ConstantStore(bo)) return true;
    std::vector<const MemberExpr*> uses;
    if (auto* me = AsThisMember(bo->getLHS())) uses.push_back(me);
    std::optional<ReduceOp> op;
    if (bo->getOpcode() == BO_AddAssign) op = ReduceOp::Add;
    else if (bo->getOpcode() == BO_SubAssign) op = ReduceOp::Sub;
    else if (bo->getOpcode() == BO_Assign) op = MinMax(bo->getLHS(), bo->getRHS(), uses);
    Write(bo->getLHS(), bo->getExprLoc(), op, uses);
    return true;
  }
  bool VisitCXXOperatorCallExpr(CXXOperatorCallExpr* op) {
    auto k = op->getOperator();
    if (k != OO_PlusEqual && k != OO_MinusEqual && k != OO_Equal && k != OO_StarEqual && k != OO_SlashEqual &&
        k != OO_PlusPlus && k != OO_MinusMinus)
      return true;
    std::vector<const MemberExpr*> uses;
    if (auto* me = AsThisMember(op->getArg(0))) uses.push_back(me);
    std::optional<ReduceOp> r;
    if (k == OO_PlusEqual) r = ReduceOp::Add;
    else if (k == OO_MinusEqual) r = ReduceOp::Sub;
    else if (k == OO_Equal) r = MinMax(op->getArg(0), op->getArg(1), uses);
    Write(op->getArg(0), op->getExprLoc(), r, uses);
    return true;
  }
  bool VisitUnaryOperator(UnaryOperator* uo) {
    if (!uo->isIncrementDecrementOp()) return true;
    // m++ and m-- on a member are reductions, as m += 1 and m -= 1 are.
    std::vector<const MemberExpr*> uses;
    std::optional<ReduceOp> op;
    if (auto* me = AsThisMember(uo->getSubExpr()); me && uo->getSubExpr()->getType()->isArithmeticType()) {
      uses.push_back(me);
      op = uo->isIncrementOp() ? ReduceOp::Add : ReduceOp::Sub;
    }
    Write(uo->getSubExpr(), uo->getExprLoc(), op, uses);
    return true;
  }
  // push_back to a member vector: an append through an atomic counter on the GPU; on the CPU a
  // lock, in the kernel's loop and in copies of the helpers on the way (LockedCopy).
  std::map<const FieldDecl*, SourceLocation> appends;
  bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
    if (auto* f = AppendTarget(call)) appends.emplace(f, call->getExprLoc());
    return true;
  }
  // A member passed to a non-const reference parameter may be written by the callee (GLSL inout).
  bool VisitCallExpr(CallExpr* call) {
    auto* fd = call->getDirectCallee();
    // An atomic's target may be written by every thread, in a helper too: no race, no reduction.
    if (IsCrossrtAtomic(fd) && call->getNumArgs() > 0) {
      if (auto* root = RootField(call->getArg(0))) (IsStdVector(root->getType()) ? vectorWrites : atomicMembers).insert(root);
      return true;
    }
    if (!fd || IsSystemDecl(fd) || isa<CXXOperatorCallExpr>(call)) return true;
    for (unsigned i = 0; i < call->getNumArgs() && i < fd->getNumParams(); ++i) {
      QualType t = fd->getParamDecl(i)->getType();
      const Expr* arg = call->getArg(i);
      if (t->isReferenceType() && !t.getNonReferenceType().isConstQualified())
        Write(arg, arg->getExprLoc(), std::nullopt, {});
      // A pointer to non-const: the callee may write what it points at (&m_v[i], m_v.data() + k).
      if (!t->isPointerType() || t->getPointeeType().isConstQualified()) continue;
      const Expr* target = arg->IgnoreParenImpCasts();
      while (auto* bo = dyn_cast<BinaryOperator>(target)) target = (bo->getLHS()->getType()->isPointerType() ? bo->getLHS() : bo->getRHS())->IgnoreParenImpCasts();
      if (auto* uo = dyn_cast<UnaryOperator>(target); uo && uo->getOpcode() == UO_AddrOf) Write(uo->getSubExpr(), arg->getExprLoc(), std::nullopt, {});
      if (auto* mc = dyn_cast<CXXMemberCallExpr>(target); mc && mc->getMethodDecl() && mc->getMethodDecl()->getName() == "data")
        if (auto* f = ThisField(mc->getImplicitObjectArgument()); f && IsStdVector(f->getType())) vectorWrites.insert(f);
    }
    return true;
  }
};

// Every other read of a reduction target inside the kernel would see a partial sum.
struct ReductionReadScanner : RecursiveASTVisitor<ReductionReadScanner> {
  Context& c;
  const WriteScanner& w;
  ReductionReadScanner(Context& ctx, const WriteScanner& ws) : c(ctx), w(ws) {}
  bool VisitMemberExpr(MemberExpr* me) {
    auto* f = dyn_cast<FieldDecl>(me->getMemberDecl());
    if (f && w.reductions.count(f) && !w.reductionUses.count(me) && isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts()))
      c.rep.Error(me->getExprLoc(), "kernel reads '" + f->getNameAsString() + "', which it also reduces",
                  "the value is only known after all threads finish: read it in the control function after the kernel");
    return true;
  }
};

// Locals declared before a kernelND_'s loop nest that its threads reduce, as they reduce members:
//   float sum = 0.0f;  for (...) { ... sum += x; best = std::max(best, y); }  m_mean = sum / n;
// Each thread accumulates its part from the identity; after the nest the parts are combined with
// the local's initial value, where the statements after the loop read it. Any other write, or a
// read inside the loop, stays an error (CheckLoopEnds, LocalReductionReads).
struct LocalReductionScanner : RecursiveASTVisitor<LocalReductionScanner> {
  Context& c;
  const std::set<const VarDecl*>& locals;
  std::map<const VarDecl*, ReduceOp> reductions;
  std::set<const Expr*> targets;         // the written expressions of the reduction statements
  std::set<const DeclRefExpr*> uses;     // the references to the locals those statements make
  LocalReductionScanner(Context& ctx, const std::set<const VarDecl*>& l) : c(ctx), locals(l) {}

  const DeclRefExpr* Ref(const Expr* e) const {
    auto* dr = dyn_cast<DeclRefExpr>(e->IgnoreParenImpCasts());
    return dr && isa<VarDecl>(dr->getDecl()) && locals.count(cast<VarDecl>(dr->getDecl())) ? dr : nullptr;
  }
  // x, or an element of a one-dimensional local array (bins[b], reduced element by element): x's
  // reference; `e` itself must have the reduced type.
  const DeclRefExpr* Target(const Expr* e) const {
    if (auto* r = Ref(e)) return r;
    auto* as = dyn_cast<ArraySubscriptExpr>(e->IgnoreParenImpCasts());
    auto* r = as ? Ref(as->getBase()) : nullptr;
    auto* arr = r ? dyn_cast<ConstantArrayType>(r->getType().getCanonicalType().getTypePtr()) : nullptr;
    return arr && !isa<ArrayType>(arr->getElementType().getCanonicalType().getTypePtr()) ? r : nullptr;
  }
  // x = min(x, v) / max(v, x) (std::, fmin/fmax, LiteMath's), or bins[k] = min(bins[k], v): the
  // operation, and the reference to x among the arguments.
  std::optional<ReduceOp> MinMax(const Expr* lhs, const DeclRefExpr* target, const Expr* rhs, const DeclRefExpr*& use) const {
    auto* call = dyn_cast<CallExpr>(rhs->IgnoreImplicit());
    if (!call || !call->getDirectCallee() || call->getNumArgs() != 2) return std::nullopt;
    const std::string n = call->getDirectCallee()->getNameAsString();
    const bool isMin = n == "min" || n == "fmin" || n == "fminf", isMax = n == "max" || n == "fmax" || n == "fmaxf";
    if (!isMin && !isMax) return std::nullopt;
    llvm::FoldingSetNodeID written;
    lhs->IgnoreParenImpCasts()->Profile(written, c.ctx, true);
    for (auto* arg : call->arguments()) {
      llvm::FoldingSetNodeID read;
      arg->IgnoreParenImpCasts()->Profile(read, c.ctx, true);
      if (auto* r = Target(arg); r && r->getDecl() == target->getDecl() && read == written) {
        use = r;
        return isMin ? ReduceOp::Min : ReduceOp::Max;
      }
    }
    return std::nullopt;
  }
  void Found(const Expr* lhs, const DeclRefExpr* target, ReduceOp op, const DeclRefExpr* other, SourceLocation loc) {
    auto* vd = cast<VarDecl>(target->getDecl());
    auto [it, fresh] = reductions.emplace(vd, op);
    if (!fresh && it->second != op)
      c.rep.Error(loc, "local '" + vd->getNameAsString() + "' is reduced with two different operations in one loop nest",
                  "use one of +=, -=, min or max per variable");
    targets.insert(lhs);
    uses.insert(target);
    if (other) uses.insert(other);
  }
  bool VisitBinaryOperator(BinaryOperator* bo) {
    auto* target = bo->isAssignmentOp() ? Target(bo->getLHS()) : nullptr;
    if (!target || !bo->getLHS()->getType()->isArithmeticType()) return true;
    const DeclRefExpr* other = nullptr;
    std::optional<ReduceOp> op;
    if (bo->getOpcode() == BO_AddAssign) op = ReduceOp::Add;
    else if (bo->getOpcode() == BO_SubAssign) op = ReduceOp::Sub;
    else if (bo->getOpcode() == BO_Assign) op = MinMax(bo->getLHS(), target, bo->getRHS(), other);
    if (op) Found(bo->getLHS(), target, *op, other, bo->getExprLoc());
    return true;
  }
  bool VisitCXXOperatorCallExpr(CXXOperatorCallExpr* call) {  // LiteMath vectors: v += x, v = min(v, x)
    auto k = call->getOperator();
    auto* target = (k == OO_PlusEqual || k == OO_MinusEqual || k == OO_Equal) ? Target(call->getArg(0)) : nullptr;
    if (!target || !GlslTypeOf(call->getArg(0)->getType())) return true;
    const DeclRefExpr* other = nullptr;
    std::optional<ReduceOp> op;
    if (k == OO_PlusEqual) op = ReduceOp::Add;
    else if (k == OO_MinusEqual) op = ReduceOp::Sub;
    else op = MinMax(call->getArg(0), target, call->getArg(1), other);
    if (op) Found(call->getArg(0), target, *op, other, call->getExprLoc());
    return true;
  }
  bool VisitUnaryOperator(UnaryOperator* uo) {  // n++ and n-- count
    auto* target = uo->isIncrementDecrementOp() ? Target(uo->getSubExpr()) : nullptr;
    if (target && uo->getSubExpr()->getType()->isArithmeticType())
      Found(uo->getSubExpr(), target, uo->isIncrementOp() ? ReduceOp::Add : ReduceOp::Sub, nullptr, uo->getExprLoc());
    return true;
  }
};

// A read of a reduced local inside the loop nest would see one thread's part.
void LocalReductionReads(Context& c, const std::string& kernel, const LocalReductionScanner& scan, const Stmt* threadBody);

}  // namespace crossrt::engine
