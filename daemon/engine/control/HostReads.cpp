// Host code of a control function that uses what kernels write on the GPU: members they write,
// member vectors they write (also through data(), and swapped ones), and output pointer parameters.
// The Vulkan class records the whole body before any of it runs, so such a use, done while
// recording, would see the value from before the call. After the last statement that records GPU
// work the uses are sound once deferred: the ...Cmd stores those statements (the host tail,
// `m_mean = m_sum / float(n);`, `m_first = m_out[0];`) as a lambda, capturing the locals they read,
// and the generated control function runs it after the kernels' results are back; when the tail
// changes a vector the kernels use, it uploads it at its end. Between kernels a plain member read
// splits the recording: the read becomes `crt_Synchronize(crt_cmd, "Solve").m_residual`, which
// submits what was recorded, waits, reads the members back and begins a new command buffer (a
// solver's `if (m_residual < tol) break;`). A host statement there that uses member vectors'
// elements (k-means moving its centroids) is split around likewise: crt_Synchronize before it, the
// vectors the kernels write read back, those it changes uploaded after it. Output parameters
// (copied back only at the end), resizing such a vector, a use inside a statement that also records
// GPU work, and a reference or lambda that reaches one later are errors there. Takes a control
// function's body; gives Control::hasHostTail, Control::synchronizes, the ...Cmd's lambda, its
// synchronised reads and the statements split around.
#include "control/ControlFunctions.h"
#include "control/ControlRewriter.h"
#include "generate/GeneratedNames.h"

using namespace clang;

namespace crossrt::engine {

namespace {

// The call that takes `e` (through casts and parentheses): the method's name where `e` is the object
// or an argument of a member call, the function's where it is an argument of a free function
// ("std::swap", "ReduceAddInit"), else "".
std::string UsingCall(ASTContext& ctx, const Expr* e) {
  DynTypedNode node = DynTypedNode::create(*e);
  for (;;) {
    const auto parents = ctx.getParents(node);
    if (parents.empty()) return "";
    node = parents[0];
    if (node.get<ImplicitCastExpr>() || node.get<ParenExpr>()) continue;
    if (auto* callee = node.get<MemberExpr>()) {
      const auto up = ctx.getParents(*callee);
      auto* call = up.empty() ? nullptr : up[0].get<CXXMemberCallExpr>();
      return call && call->getMethodDecl() ? call->getMethodDecl()->getNameAsString() : "";
    }
    if (auto* call = node.get<CXXMemberCallExpr>(); call && call->getMethodDecl())  // an argument of a method: m_a.swap(m_b)
      return call->getMethodDecl()->getNameAsString();
    if (auto* call = node.get<CallExpr>(); call && call->getDirectCallee())
      return (call->getDirectCallee()->isInStdNamespace() ? "std::" : "") + call->getDirectCallee()->getNameAsString();
    return "";
  }
}

// The call among `calls` whose source range holds `e`, or null.
const Expr* EnclosingCall(const SourceManager& sm, const std::vector<const Expr*>& calls, const Expr* e) {
  for (const Expr* call : calls) {
    const SourceRange r = call->getSourceRange();
    if (!sm.isBeforeInTranslationUnit(e->getBeginLoc(), r.getBegin()) && !sm.isBeforeInTranslationUnit(r.getEnd(), e->getEndLoc())) return call;
  }
  return nullptr;
}

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

// The member vectors a control function's kernels may write: those kernels store to, those whose
// data() it hands to a kernel's non-const pointer, and those it swaps (either may then hold what
// the kernels wrote).
std::set<std::string> VectorsKernelsWrite(Context& c, const FunctionDecl* control) {
  std::set<std::string> written;
  for (const Member& m : c.model.members)
    if (m.kind == MemberKind::Vector && m.writtenByKernels) written.insert(m.name);
  struct Finder : RecursiveASTVisitor<Finder> {
    std::set<std::string>& written;
    explicit Finder(std::set<std::string>& w) : written(w) {}
    void Vector(const Expr* e) {
      if (auto* f = ThisField(e); f && IsStdVector(f->getType().getNonReferenceType())) written.insert(f->getNameAsString());
    }
    bool VisitCallExpr(CallExpr* call) {
      auto* fd = call->getDirectCallee();
      if (!fd) return true;
      if (fd->getName() == "swap") {  // std::swap(m_a, m_b) or m_a.swap(m_b)
        for (const Expr* arg : call->arguments()) Vector(arg);
        if (auto* mc = dyn_cast<CXXMemberCallExpr>(call)) Vector(mc->getImplicitObjectArgument());
      }
      if (auto* md = dyn_cast<CXXMethodDecl>(fd); md && IsKernelName(md->getName()))
        for (unsigned i = 0; i < call->getNumArgs() && i < md->getNumParams(); ++i) {
          const QualType t = md->getParamDecl(i)->getType();
          if (!t->isPointerType() || t->getPointeeType().isConstQualified()) continue;
          const Expr* arg = call->getArg(i)->IgnoreParenImpCasts();
          if (auto* bo = dyn_cast<BinaryOperator>(arg); bo && bo->getOpcode() == BO_Add) arg = bo->getLHS()->IgnoreParenImpCasts();
          if (auto* data = dyn_cast<CXXMemberCallExpr>(arg); data && data->getMethodDecl() && data->getMethodDecl()->getName() == "data")
            Vector(data->getImplicitObjectArgument());
        }
      return true;
    }
  } finder(written);
  finder.TraverseStmt(const_cast<Stmt*>(control->getBody()));
  return written;
}

// The uses of this object's members in `s` (m_x, this->m_x), in the order written.
std::vector<const MemberExpr*> ThisMemberUses(const Stmt* s) {
  struct Finder : RecursiveASTVisitor<Finder> {
    std::vector<const MemberExpr*> uses;
    bool VisitMemberExpr(MemberExpr* me) {
      if (isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts())) uses.push_back(me);
      return true;
    }
  } finder;
  finder.TraverseStmt(const_cast<Stmt*>(s));
  return finder.uses;
}

// Whether host code in `s` uses one of the member vectors `written` (its elements, an iterator, the
// whole vector), other than asking its size or handing it to a kernel or a library call.
bool UsesWrittenVector(Context& c, const std::set<std::string>& written, const Stmt* s) {
  KernelCallFinder gpu(c.cls);
  gpu.TraverseStmt(const_cast<Stmt*>(s));
  auto& sm = c.ctx.getSourceManager();
  static const std::set<std::string> sizes = {"size", "capacity", "empty"};
  for (const MemberExpr* me : ThisMemberUses(s)) {
    if (!written.count(me->getMemberDecl()->getNameAsString()) || sizes.count(UsingCall(c.ctx, me))) continue;
    if (!EnclosingCall(sm, gpu.calls, me)) return true;
  }
  return false;
}

// Where `s` first records GPU work: a kernel call (or a per-thread function's), a library call on
// device data, LiteMath's ReduceAddInit, clear() of a vector kernels append to, or a swap of member
// vectors. Invalid if none.
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
      // A swap of member vectors swaps their device buffers while recording (MemberSwaps.cpp): it
      // stays in the ...Cmd, never in the host tail, which would swap the host's copies alone.
      if (fd && fd->getName() == "swap")
        for (const Expr* arg : call->arguments())
          if (auto* f = ThisField(arg); f && IsStdVector(f->getType().getNonReferenceType())) gpu = true;
      if (gpu && at.isInvalid()) at = call->getBeginLoc();
      return true;
    }
  } others(c);
  others.TraverseStmt(const_cast<Stmt*>(s));
  auto& sm = c.ctx.getSourceManager();
  if (first.isInvalid() || (others.at.isValid() && sm.isBeforeInTranslationUnit(others.at, first))) first = others.at;
  return first;
}

// The first parent of `n`, or an empty node at the top.
DynTypedNode ParentOf(ASTContext& ctx, const DynTypedNode& n) {
  const auto parents = ctx.getParents(n);
  return parents.empty() ? DynTypedNode() : parents[0];
}

// Whether `me` (a member vector) is only read where it stands: an element read as a value
// (m_v[i], m_v[i].x, m_v.at(i), m_v.front()), or iterated by value or const reference. Anything
// else (an element assigned, a non-const reference, an iterator or data() handed on) may change it.
bool ReadOnlyUse(ASTContext& ctx, const MemberExpr* me) {
  DynTypedNode node = DynTypedNode::create(*me);
  // Up to the element: through casts and parentheses, a subscript, at/front/back, and a field of it.
  bool element = false;
  for (;;) {
    const DynTypedNode up = ParentOf(ctx, node);
    if (auto* cast = up.get<ImplicitCastExpr>()) {
      if (cast->getCastKind() == CK_LValueToRValue) return element;
      node = up;
      continue;
    }
    if (up.get<ParenExpr>()) {
      node = up;
      continue;
    }
    if (auto* op = up.get<CXXOperatorCallExpr>(); op && op->getOperator() == OO_Subscript && !element) {
      element = true, node = up;
      continue;
    }
    if (up.get<MemberExpr>()) {  // m_v.size(), m_v.at(i), or a field of an element
      const DynTypedNode call = ParentOf(ctx, up);
      if (auto* mc = call.get<CXXMemberCallExpr>()) {
        const std::string method = mc->getMethodDecl() ? mc->getMethodDecl()->getNameAsString() : "";
        if (method == "size" || method == "empty" || method == "capacity") return true;
        if (!element && (method == "at" || method == "front" || method == "back")) {
          element = true, node = call;
          continue;
        }
        return element && mc->getMethodDecl()->isConst();  // a const method of an element
      }
      if (!element) return false;
      node = up;  // m_v[i].x
      continue;
    }
    // for (float v : m_v) or for (const T& v : m_v): read; for (T& v : m_v): written.
    if (auto* range = up.get<VarDecl>(); range && !element) {
      const DynTypedNode declStmt = ParentOf(ctx, up);
      if (auto* loop = ParentOf(ctx, declStmt).get<CXXForRangeStmt>(); loop && loop->getRangeStmt() == declStmt.get<DeclStmt>()) {
        const QualType t = loop->getLoopVariable()->getType();
        return !t->isReferenceType() || t.getNonReferenceType().isConstQualified();
      }
    }
    return false;
  }
}

// Whether the host may reach the elements `me` names after the statement that holds it: through a
// lambda around it, or a local reference, pointer or iterator bound to the vector or an element
// (`auto& v = m_v;`, `float* p = m_v.data();`). Says how, or "" when it cannot.
std::string LaterAccess(ASTContext& ctx, const MemberExpr* me) {
  for (DynTypedNode n = ParentOf(ctx, DynTypedNode::create(*me)); !n.getNodeKind().isNone(); n = ParentOf(ctx, n))
    if (n.get<LambdaExpr>()) return "a lambda, which may run after the statement";
  DynTypedNode node = DynTypedNode::create(*me);
  for (;;) {
    const DynTypedNode up = ParentOf(ctx, node);
    if (up.get<ImplicitCastExpr>() || up.get<ParenExpr>() || up.get<MaterializeTemporaryExpr>() || up.get<CXXBindTemporaryExpr>() ||
        up.get<ExprWithCleanups>() || up.get<CXXConstructExpr>()) {
      node = up;
      continue;
    }
    if (auto* uo = up.get<UnaryOperator>(); uo && uo->getOpcode() == UO_AddrOf) {
      node = up;
      continue;
    }
    if (auto* op = up.get<CXXOperatorCallExpr>(); op && op->getOperator() == OO_Subscript) {
      node = up;
      continue;
    }
    if (up.get<MemberExpr>()) {  // m_v.data(), m_v.begin(), m_v.at(i), a field of an element
      const DynTypedNode call = ParentOf(ctx, up);
      node = call.get<CXXMemberCallExpr>() ? call : up;
      continue;
    }
    auto* var = up.get<VarDecl>();
    if (!var || var->isImplicit()) return "";  // used where it stands (or a range-for's own range)
    const QualType t = var->getType();
    const bool mutableAlias = (t->isReferenceType() && !t.getNonReferenceType().isConstQualified()) ||
                              (t->isPointerType() && !t->getPointeeType().isConstQualified()) ||
                              (t->isRecordType() && t.getAsString().find("iterator") != std::string::npos);
    return mutableAlias ? "the local '" + var->getNameAsString() + "', which may change it after the statement" : "";
  }
}

// Calls on a member vector that need nothing on the host between kernel calls (LiteMath's
// ReduceAddInit and ReduceAddComplete are GPU work of their own), and those that resize it.
const std::set<std::string> kHarmless = {"size", "capacity", "empty", "swap", "std::swap", "reserve", "ReduceAddInit", "ReduceAddComplete"};
const std::set<std::string> kResizing = {"push_back", "emplace_back", "pop_back", "resize", "assign", "clear", "insert", "erase", "emplace", "shrink_to_fit"};

// The member vectors kernels use (or that `alsoUsed` names: those handed to them through data() or
// swapped) whose elements `s` may change, as "hostExpr|name". A resize is not among them: the next
// call gives a resized vector a new device buffer, filled.
std::set<std::string> ChangedDeviceVectors(Context& c, const std::set<std::string>& alsoUsed, const Stmt* s) {
  std::set<std::string> changed;
  for (const MemberExpr* me : ThisMemberUses(s)) {
    auto* f = dyn_cast<FieldDecl>(me->getMemberDecl());
    const Member* m = f ? FindMember(c.model, f->getNameAsString()) : nullptr;
    if (!m || m->kind != MemberKind::Vector || !(m->usedByKernels || alsoUsed.count(m->name)) || m->appendedByKernels) continue;
    const std::string call = UsingCall(c.ctx, me);
    if (kHarmless.count(call) || kResizing.count(call) || ReadOnlyUse(c.ctx, me)) continue;
    changed.insert(m->hostExpr + "|" + m->name);
  }
  return changed;
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
  // records GPU work (its next round reads what this one's kernels write). A member read there
  // splits the recording (m_syncReads); an output parameter, copied back only at the end, cannot.
  KernelCallFinder kernelCalls(m_c.cls);
  kernelCalls.TraverseStmt(const_cast<Stmt*>(m_def->getBody()));
  for (int i = first; i <= last; ++i) {
    const bool loop = isa<ForStmt, WhileStmt, DoStmt, CXXForRangeStmt>(statements[i]) && FirstGpuWork(m_c, statements[i]).isValid();
    for (const auto& [read, name] : KernelWrittenReads(m_c, m_def, statements[i])) {
      if (!loop && !sm.isBeforeInTranslationUnit(firstWork, read->getBeginLoc())) continue;
      const Expr* call = EnclosingCall(sm, kernelCalls.calls, read);
      if (auto* me = dyn_cast<MemberExpr>(read); me && !call) {
        m_syncReads.push_back(me);
        continue;
      }
      // An argument of a kernel call (kernel1D_Scale(n, 1.0f / m_total)): the call synchronises first.
      auto* kernelCall = dyn_cast_or_null<CXXMemberCallExpr>(call);
      if (isa<MemberExpr>(read) && kernelCall && kernelCall->getMethodDecl() && IpvDims(kernelCall->getMethodDecl()->getName())) {
        m_syncCalls.insert(kernelCall);
        m_syncReads.push_back(cast<MemberExpr>(read));  // for the note; its text stays
        continue;
      }
      if (isa<MemberExpr>(read))
        m_c.rep.RecordingError(read->getExprLoc(), "'" + m_ctrl.name + "' passes '" + name + "', which kernels write on the GPU, to a call recorded before the kernels before it run: it would get the value from before them",
                               "read '" + name + "' inside the kernel, which sees the GPU's copy, or pass it to a kernel1D_/kernel2D_/kernel3D_ call (which waits for it)");
      else
        m_c.rep.RecordingError(read->getExprLoc(), "control function '" + m_ctrl.name + "' uses '" + name +
                                   "' between kernel calls, but kernels write it on the GPU, and it is copied back only when the call returns",
                               "read it inside a kernel, which sees the GPU's copy, or after the last kernel call: code there runs once the results are back");
    }
  }
  // The tail moves only when it needs to: when it reads what the kernels wrote, or changes a vector
  // they use (uploaded at its end, or the next call's kernels would see the copy from before).
  bool reads = false;
  const std::set<std::string> vectors = VectorsKernelsWrite(m_c, m_def);
  for (size_t i = size_t(last) + 1; i < statements.size(); ++i) {
    reads = reads || !KernelWrittenReads(m_c, m_def, statements[i]).empty() || UsesWrittenVector(m_c, vectors, statements[i]);
    const std::set<std::string> changed = ChangedDeviceVectors(m_c, vectors, statements[i]);
    m_tailUploads.insert(changed.begin(), changed.end());
  }
  if (!reads && m_tailUploads.empty()) return;
  m_tail.assign(statements.begin() + last + 1, statements.end());
}


void ControlRewriter::CheckHostVectorUses() {
  auto* body = dyn_cast<CompoundStmt>(m_def->getBody());
  if (!body) return;
  auto& sm = m_c.ctx.getSourceManager();
  const std::vector<const Stmt*> statements(body->body_begin(), body->body_end());
  int last = -1;
  SourceLocation firstWork;
  for (int i = 0; i < int(statements.size()); ++i)
    if (SourceLocation at = FirstGpuWork(m_c, statements[i]); at.isValid()) {
      if (firstWork.isInvalid()) firstWork = at;
      last = i;
    }
  if (last < 0) return;
  KernelCallFinder gpu(m_c.cls);  // kernel and library calls: what they take is the GPU's business
  gpu.TraverseStmt(const_cast<Stmt*>(m_def->getBody()));
  for (int i = 0; i <= last; ++i) {
    const bool loop = isa<ForStmt, WhileStmt, DoStmt, CXXForRangeStmt>(statements[i]) && FirstGpuWork(m_c, statements[i]).isValid();
    for (const MemberExpr* me : ThisMemberUses(statements[i])) {
      auto* f = dyn_cast<FieldDecl>(me->getMemberDecl());
      const Member* m = f ? FindMember(m_c.model, f->getNameAsString()) : nullptr;
      if (!m || m->kind != MemberKind::Vector || !m->usedByKernels || m->appendedByKernels || EnclosingCall(sm, gpu.calls, me)) continue;
      // size() and the like, and std::swap's arguments, are the translated uses.
      const std::string call = UsingCall(m_c.ctx, me);
      if (kHarmless.count(call)) continue;
      if (kResizing.count(call)) {
        m_c.rep.RecordingError(me->getExprLoc(), "control function '" + m_ctrl.name + "' resizes '" + m->name +
                                   "' before its last kernel call, but its kernels use the device buffer sized when the call began",
                               "size it before the call (the next call makes its buffer anew), or keep its size and change its elements, which is translated; "
                               "a swap of two member vectors (std::swap(" + m->name + ", other)) is translated too");
        continue;
      }
      const bool written = m->writtenByKernels || std::find(m_ctrl.vectorsWritten.begin(), m_ctrl.vectorsWritten.end(), m->name) != m_ctrl.vectorsWritten.end();
      const bool after = loop || sm.isBeforeInTranslationUnit(firstWork, me->getBeginLoc());
      const bool changes = !ReadOnlyUse(m_c.ctx, me);
      if (!changes && !(written && after)) continue;  // a read of what only the host writes
      if (const std::string how = changes ? LaterAccess(m_c.ctx, me) : ""; !how.empty()) {
        m_c.rep.RecordingError(me->getExprLoc(), "control function '" + m_ctrl.name + "' lets host code reach '" + m->name + "' between kernel calls through " +
                                   how + ": the generated class cannot tell when to upload it",
                               "index '" + m->name + "' itself in the statements that change it (" + m->name + "[i] = ...): each is then synchronised with the GPU");
        continue;
      }
      if (!SynchronizeAround(me, *m, written, changes))
        m_c.rep.RecordingError(me->getExprLoc(), "control function '" + m_ctrl.name + "' " + (changes ? "changes" : "reads") + " '" + m->name +
                                   "' on the host in a statement that also records GPU work, between kernel calls",
                               "use it in a statement of its own, before or after the kernel call (e.g. 'const auto v = " + m->name +
                                   "[i];'): there the generated class waits for the GPU, reads the vector back and uploads it again");
    }
  }
}

bool ControlRewriter::SynchronizeAround(const MemberExpr* use, const Member& m, bool download, bool upload) {
  // The outermost statement around the use that records no GPU work and is one of a block's: the
  // vector is synchronised once around it (around a whole host loop, say, not per element).
  const Stmt* chosen = nullptr;
  DynTypedNode node = DynTypedNode::create(*use);
  for (;;) {
    const auto parents = m_c.ctx.getParents(node);
    if (parents.empty()) break;
    if (auto* block = parents[0].get<CompoundStmt>()) {
      const Stmt* child = node.get<Stmt>();
      if (!child || FirstGpuWork(m_c, child).isValid()) break;
      chosen = child;
      if (block == m_def->getBody()) break;
    }
    node = parents[0];
  }
  if (!chosen) return false;
  HostVectorSync& sync = m_vectorSyncs[chosen];
  if (sync.downloads.empty() && sync.uploads.empty()) m_vectorSyncOrder.push_back(chosen);
  if (download) sync.downloads.insert(m.name);
  if (upload) sync.uploads.insert(m.name);
  sync.at = chosen->getBeginLoc();
  return true;
}

void ControlRewriter::SynchronizeHostVectors() {
  if (m_vectorSyncs.empty()) return;
  m_ctrl.synchronizes = true;
  auto& sm = m_c.ctx.getSourceManager();
  const auto& lang = m_c.ctx.getLangOpts();
  const std::string buffers = generated::kVectorCopies + ".";
  for (const Stmt* s : m_vectorSyncOrder) {
    const HostVectorSync& sync = m_vectorSyncs[s];
    std::string before = "crt_Synchronize(crt_cmd, \"" + m_ctrl.name + "\");  // crossrt: the host uses member vectors below: wait for the GPU\n";
    std::string after, names;
    for (const std::string& name : sync.downloads) {
      const Member* m = FindMember(m_c.model, name);
      before += "crossrt::DownloadVector(" + buffers + name + ", " + m->hostExpr + ");\n";
    }
    for (const std::string& name : sync.uploads) {
      const Member* m = FindMember(m_c.model, name);
      after += "\ncrossrt::UploadVector(" + buffers + name + ", " + m->hostExpr + ");  // crossrt: the host changed it above";
    }
    for (const std::string& name : sync.downloads) names += (names.empty() ? "'" : ", '") + name + "'";
    std::string uploaded;
    for (const std::string& name : sync.uploads) uploaded += (uploaded.empty() ? "'" : ", '") + name + "'";
    m_gpu.InsertTextBefore(s->getBeginLoc(), before);
    SourceLocation end = Lexer::findLocationAfterToken(s->getEndLoc(), tok::semi, sm, lang, false);
    if (end.isInvalid()) end = Lexer::getLocForEndOfToken(s->getEndLoc(), 0, sm, lang);  // a block or loop
    if (!after.empty()) m_gpu.InsertTextAfter(end, after);
    if (m_c.rep.RecordingRules())
      m_c.rep.Note(sync.at, "'" + m_ctrl.name + "' uses member vectors on the host between kernel calls: on Vulkan the recording is split before this statement (the work recorded so far is submitted and waited for" +
                                (names.empty() ? "" : ", and " + names + " read back") + ")" + (uploaded.empty() ? "" : " and " + uploaded + " uploaded after it") +
                                ", a round trip to the GPU each time it runs");
  }
}

void ControlRewriter::SplitAtHostReads() {
  if (m_syncReads.empty()) return;
  m_ctrl.synchronizes = true;
  std::set<std::string> named;
  auto& sm = m_c.ctx.getSourceManager();
  for (const MemberExpr* me : m_syncReads) {
    const std::string name = me->getMemberDecl()->getNameAsString();
    const bool inCall = std::any_of(m_syncCalls.begin(), m_syncCalls.end(), [&](const CallExpr* call) {
      return !sm.isBeforeInTranslationUnit(me->getBeginLoc(), call->getBeginLoc()) && !sm.isBeforeInTranslationUnit(call->getEndLoc(), me->getEndLoc());
    });
    if (!inCall) m_gpu.ReplaceText(me->getSourceRange(), "crt_Synchronize(crt_cmd, \"" + m_ctrl.name + "\")." + name);
    if (m_c.rep.RecordingRules() && named.insert(name).second)
      m_c.rep.Note(me->getExprLoc(), "'" + m_ctrl.name + "' reads '" + name + "', which its kernels write, between kernel calls: on Vulkan the recording is split there " +
                                         "(the work recorded so far is submitted and waited for, and the members kernels write are read back), a round trip to the GPU each time it runs");
  }
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
      m_c.rep.RecordingError(vd->getLocation(), "the code of '" + m_ctrl.name + "' after its last kernel reads '" + vd->getNameAsString() +
                             "', whose elements are the GPU's", "make it a member, which the generated class copies back");
  std::string captures = "this";
  for (const std::string& name : uses.captured) captures += ", " + name;
  m_ctrl.hasHostTail = true;
  std::string uploads;
  for (const std::string& upload : m_tailUploads) {
    const std::string host = upload.substr(0, upload.find('|')), name = upload.substr(upload.find('|') + 1);
    uploads += "\ncrossrt::UploadVector(" + generated::kVectorCopies + "." + name + ", " + host + ");";
  }
  m_gpu.ReplaceText(range, "crt_hostTail_" + m_ctrl.name + " = [" + captures + "]() mutable {\n" +
                               std::string(Lexer::getSourceText(range, sm, m_c.ctx.getLangOpts())) + uploads + "\n};");
}

}  // namespace crossrt::engine
