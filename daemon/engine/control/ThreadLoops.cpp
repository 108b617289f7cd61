// Thread loops in control functions: `for (y) for (x) { kernel_A(x, y, &local); ... }`, RTV kernels
// called per thread. One nest of one kernel is one dispatch; several kernels sharing per-thread locals
// are a megakernel or a wavefront of dispatches (paper 2.1, 4.4).

#include "print/Printers.h"
#include "analyse/AnalysisContext.h"
#include "analyse/AstQueries.h"
#include "control/ControlFunctions.h"
#include "control/ControlRewriter.h"
#include "analyse/LoopShape.h"
#include "analyse/Members.h"
#include "analyse/Naming.h"

#include <algorithm>

using namespace clang;

namespace crossrt::engine {

const Expr* ControlRewriter::Resolve(const Expr* e) const {
  auto* dr = dyn_cast<DeclRefExpr>(e->IgnoreCasts()->IgnoreParens());
  auto* p = dr ? dyn_cast<ParmVarDecl>(dr->getDecl()) : nullptr;
  auto it = p ? m_inlined.find(p) : m_inlined.end();
  return it == m_inlined.end() ? e : Resolve(it->second);
}

std::set<const VarDecl*> ControlRewriter::ThreadIdVars(const Stmt* s) {
  struct Finder : RecursiveASTVisitor<Finder> {
    const ControlRewriter& rw;
    std::set<const VarDecl*> vars;
    explicit Finder(const ControlRewriter& r) : rw(r) {}
    bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
      auto* md = call->getMethodDecl();
      if (!md || !IsKernelName(md->getName()) || IpvDims(md->getName())) return true;
      for (unsigned i = 0; i < call->getNumArgs() && i < md->getNumParams(); ++i)
        if (IsThreadIdName(md->getParamDecl(i)->getName()))
          if (auto* dr = dyn_cast<DeclRefExpr>(rw.Resolve(call->getArg(i))->IgnoreCasts()->IgnoreParens()))
            if (auto* vd = dyn_cast<VarDecl>(dr->getDecl())) vars.insert(vd);
      return true;
    }
  } finder(*this);
  finder.TraverseStmt(const_cast<Stmt*>(s));
  return finder.vars;
}

bool ControlRewriter::TryThreadLoop(const ForStmt* outerLoop) {
  // The innermost body a call of a per-thread function (kernel_slicer's ...Block form)? Then the
  // thread loop's body is that function's, its parameters bound to the call's arguments.
  m_inlined.clear();
  m_perThread = nullptr;
  const Stmt* innermost = outerLoop;
  while (auto* fs = dyn_cast_or_null<ForStmt>(innermost)) innermost = SingleStatement(fs->getBody());
  const FunctionDecl* perThread = nullptr;
  if (auto* e = dyn_cast_or_null<Expr>(innermost))
    if (auto* call = dyn_cast<CXXMemberCallExpr>(e->IgnoreImplicit()); call && IsPerThreadFunction(call->getMethodDecl(), m_c.cls)) {
      call->getMethodDecl()->hasBody(perThread);
      for (unsigned i = 0; i < call->getNumArgs() && i < perThread->getNumParams(); ++i) m_inlined[perThread->getParamDecl(i)] = call->getArg(i);
      m_perThread = perThread;
    }
  const std::set<const VarDecl*> idVars = ThreadIdVars(perThread ? perThread->getBody() : outerLoop);
  ThreadLoop tl;
  const Stmt* body = outerLoop;
  while (auto* fs = dyn_cast_or_null<ForStmt>(body)) {
    LoopHeader h;
    if (!LoopShapeProblem(m_c.ctx, fs, h).empty() || !idVars.count(h.var)) break;
    tl.loops.push_back(h);
    body = SingleStatement(fs->getBody());
  }
  if (tl.loops.empty()) {
    m_inlined.clear();
    m_perThread = nullptr;
    return false;
  }
  m_inlineDepth = -1;
  if (perThread && body == innermost) {
    body = perThread->getBody();
    m_inlineDepth = 0;  // the thread loop's body is the per-thread function's
  }
  else if (auto* e = dyn_cast_or_null<Expr>(body); e && isa<CXXMemberCallExpr>(e->IgnoreImplicit())) return false;  // one kernel: an RTV nest
  for (auto& h : tl.loops) {
    Expr::EvalResult r;
    if (!(h.start->EvaluateAsInt(r, m_c.ctx) && r.Val.getInt() == 0))
      Error(tl, h.start->getBeginLoc(), "a thread loop of '" + m_ctrl.name + "' must start at 0", "start at 0 and add the offset inside the kernels");
  }
  // Locals first: kernel calls and host loops are checked against them.
  struct LocalFinder : RecursiveASTVisitor<LocalFinder> {
    std::set<const VarDecl*>& out;
    explicit LocalFinder(std::set<const VarDecl*>& o) : out(o) {}
    bool VisitVarDecl(VarDecl* vd) { out.insert(vd); return true; }
  } localFinder(tl.locals);
  localFinder.TraverseStmt(const_cast<Stmt*>(body));
  if (perThread && body != perThread->getBody())  // the call in a pass loop: its locals too
    localFinder.TraverseStmt(perThread->getBody());

  const unsigned index = ++m_threadLoops;
  tl.mega.name = m_ctrl.name + "_Megakernel" + (index > 1 ? std::to_string(index) : "");
  tl.mega.rtv = true;
  tl.mega.megakernelOf = m_ctrl.name;
  tl.mega.sourceFile = m_ctrl.sourceFile;
  tl.mega.dims = unsigned(tl.loops.size());
  // The ISPC class runs the body in SIMD lanes (IspcThreadLoops.cpp).
  std::unique_ptr<KernelPrinter> bodyPrinter = MakePrinter(m_c.model, m_c.ctx, m_c.cls, m_c.rep);
  KernelPrinter& printer = *bodyPrinter;
  for (auto& s : ClassStructNames(m_c.model)) printer.predeclaredStructs.insert(s);
  for (auto& [param, arg] : m_inlined) printer.renames[param] = printer.Expr(Resolve(arg));  // read through
  std::string glsl = ThreadBodyGlsl(tl, printer, body, 1);
  if (!tl.ok) return true;
  for (auto* f : printer.Uses().plainMembers)
    if (auto* m = FindMember(m_c.model, f->getNameAsString())) m->usedByKernels = true;
  if (!printer.Uses().memberVectors.empty())
    Error(tl, outerLoop->getBeginLoc(), "the host code of a thread loop of '" + m_ctrl.name + "' uses member vectors",
          "count host loops with plain members, parameters or constants; move other work into a kernel");
  tl.mega.functionList = printer.Functions();  // helpers the body calls (float x = testFun();), ahead of the kernels'
  const bool axesCovered = tl.axisOf.size() == tl.loops.size() &&
                           std::all_of(tl.axisOf.begin(), tl.axisOf.end(), [&](const auto& x) { return x.second < tl.loops.size(); });
  if (!axesCovered) {
    if (tl.ok)
      Error(tl, outerLoop->getBeginLoc(), "the loops of a thread loop of '" + m_ctrl.name + "' do not match the thread ids of its kernels",
            "with one loop pass it as tid (or tidX), with two as tidX and tidY, with three as tidX, tidY and tidZ");
    return true;
  }

  // The megakernel's signature: thread ids (x first), then the control function's variables it reads.
  std::vector<const VarDecl*> byAxis(tl.loops.size());
  for (auto& [var, axis] : tl.axisOf) byAxis[axis] = var;
  std::string signature;
  for (unsigned a = 0; a < byAxis.size(); ++a) {
    KernelParam id;
    id.name = byAxis[a]->getNameAsString();
    id.glslName = KernelPrinter::SafeName(id.name);
    id.glslType = GlslTypeOf(byAxis[a]->getType()).value_or("int");
    id.isThreadId = true;
    tl.mega.params.push_back(id);
    tl.mega.threadAxes.push_back(a);
    signature += (a ? ", " : "") + id.glslType + " " + id.glslName;
    for (auto& h : tl.loops)
      if (h.var == byAxis[a]) tl.counts += ", " + CountExpr(m_c, h);
  }
  std::vector<KernelParam> values;
  for (auto* vd : tl.outer) {  // in the order the body first reads them: stable text
    QualType t = vd->getType().getNonReferenceType().getUnqualifiedType();
    auto g = GlslTypeOf(t);
    auto layout = Std430Layout(m_c.ctx, t, false);
    if (!g || t->isPointerType() || !layout || !FitsClassData(m_c.ctx, t)) {
      Error(tl, vd->getLocation(), "'" + vd->getNameAsString() + "' is read by the thread loop of '" + m_ctrl.name + "', but its type cannot be passed to the GPU",
            "use int, uint, float or LiteMath types for values the thread loop reads");
      continue;
    }
    KernelParam v;
    v.name = vd->getNameAsString();
    v.glslName = KernelPrinter::SafeName(v.name);
    v.glslType = *g;
    v.valueCppType = v.cppType = CppTypeName(m_c.ctx, t);
    v.std430Align = unsigned(layout->align);
    values.push_back(v);
    auto [base, dims] = SplitArray(v.glslType);
    signature += ", " + base + " " + v.glslName + dims;
    tl.hostArgs += ", " + v.name;
  }
  for (auto& v : values) tl.mega.params.push_back(v);
  if (!tl.ok) return true;
  if (m_c.model.forIspc && IspcThreadLoop(tl, glsl, outerLoop)) {
    m_c.model.megakernels.push_back(tl.mega);
    m_inlined.clear();
    m_perThread = nullptr;
    return true;
  }
  if (!tl.wavefrontOnly.empty() && tl.megakernelOnly) {
    Error(tl, tl.wavefrontOnlyAt, tl.wavefrontOnly, "rename one of them: the megakernel, which this thread loop needs, binds each kernel's buffers under the parameter's name");
    return true;
  }
  if (!tl.wavefrontOnly.empty())
    m_c.rep.Note(tl.wavefrontOnlyAt, "the thread loop of '" + m_ctrl.name + "' runs one dispatch per kernel call (wavefront) in both execution modes: " + tl.wavefrontOnly);
  // After the counts; none where a kernel's result ends a thread's loop (the megakernel in both modes).
  const std::string wavefront = tl.megakernelOnly ? "" : ThreadBodyCpp(tl, body);
  tl.mega.glslBody = "// from " + m_c.cls->getNameAsString() + "::" + m_ctrl.name + " (" + m_ctrl.sourceFile +
                     "): the body of its thread loop, each kernel call a function call\nvoid " + tl.mega.name + "(" + signature + ")\n{\n" + glsl + "}\n";
  if (tl.wavefrontOnly.empty()) m_c.model.megakernels.push_back(tl.mega);

  // Vulkan: both modes, picked when recording.
  std::string states;
  for (auto& [local, buffer] : tl.stateBuffers) {
    if (!tl.passed.count(local)) continue;  // no kernel sees it: nothing to keep between dispatches
    std::string cppType = CppTypeName(m_c.ctx, local->getType().getUnqualifiedType());
    m_ctrl.threadStates.push_back({buffer, cppType, local->getNameAsString()});
    auto start = tl.startValues.find(local);
    states += "crossrt::EnsureSize(crt_ctx, crt_threadState." + buffer + ", sizeof(" + cppType + ") * std::max<size_t>(1, crt_threads));\n"
              "crossrt::FillCmd(crt_cmd, crt_threadState." + buffer + ".View(), sizeof(" + cppType + ") * crt_threads, " +
              (start == tl.startValues.end() ? "0);  // " + local->getNameAsString() + " starts at zero\n"
                                             : "crossrt::Bits32(static_cast<" + cppType + ">(" + start->second + ")));  // " + local->getNameAsString() +
                                                   " starts at " + start->second + "\n");
  }
  std::string threads;
  for (auto& h : tl.loops) threads += (threads.empty() ? "" : " * ") + std::string("size_t(") + CountExpr(m_c, h) + ")";
  std::string text =
      "if (crt_executionMode == crossrt::ExecutionMode::Megakernel)  // the whole loop body in one shader\n" + tl.mega.name + "Cmd(crt_cmd" + tl.counts + tl.hostArgs +
      ");\nelse  // wavefront: one dispatch per kernel call, each thread's locals in buffers between them\n{\n" +
      (states.empty() ? "" : "const size_t crt_threads = " + threads + ";\n" + states) + wavefront + "}\n";
  if (!tl.wavefrontOnly.empty())
    text = "// Two kernels' parameters of one name get different buffers here, which the megakernel would\n"
           "// bind under one name: one dispatch per kernel call (wavefront) in both execution modes.\n{\n" +
           (states.empty() ? "" : "const size_t crt_threads = " + threads + ";\n" + states) + wavefront + "}\n";
  if (tl.megakernelOnly) {
    m_ctrl.threadStates.erase(m_ctrl.threadStates.end() - long(std::count_if(tl.stateBuffers.begin(), tl.stateBuffers.end(),
                                                                             [&](const auto& x) { return tl.passed.count(x.first) > 0; })),
                              m_ctrl.threadStates.end());
    text = "// A kernel's result ends a thread's loop here, at a time of the thread's own: the whole loop\n"
           "// body runs in one shader (the megakernel) in both execution modes.\n" +
           tl.mega.name + "Cmd(crt_cmd" + tl.counts + tl.hostArgs + ");\n";
  }
  SourceLocation end = Lexer::findLocationAfterToken(outerLoop->getEndLoc(), tok::semi, m_c.ctx.getSourceManager(), m_c.ctx.getLangOpts(), false);
  CharSourceRange range = end.isValid() ? CharSourceRange::getCharRange(outerLoop->getBeginLoc(), end) : CharSourceRange::getTokenRange(outerLoop->getSourceRange());
  m_gpu.ReplaceText(range, text);
  // CPU: the loop as written, its threads on all cores (the locals are private to each iteration).
  ParallelOnCpu(outerLoop, tl.loops.front(), tl.loops.size());
  m_inlined.clear();
  m_perThread = nullptr;
  return true;
}

std::string ControlRewriter::StateBuffer(const ThreadLoop& tl, const VarDecl* vd) {
  for (auto& [local, buffer] : tl.stateBuffers)
    if (local == vd) return buffer;
  return "";
}

void ControlRewriter::Error(ThreadLoop& tl, SourceLocation loc, const std::string& message, const std::string& hint) {
  m_c.rep.GpuError(loc, message, hint);
  tl.ok = false;
}

void ControlRewriter::ForEachVariable(const ThreadLoop& tl, const Expr* e,
                                      const std::function<void(const DeclRefExpr*, const VarDecl*, bool)>& visit) const {
  struct Finder : RecursiveASTVisitor<Finder> {
    std::vector<const DeclRefExpr*> refs;
    bool VisitDeclRefExpr(DeclRefExpr* dr) { refs.push_back(dr); return true; }
  } finder;
  finder.TraverseStmt(const_cast<Expr*>(e));
  for (auto* dr : finder.refs) {
    if (auto* p = dyn_cast<ParmVarDecl>(dr->getDecl()); p && m_inlined.count(p)) {  // a per-thread function's parameter
      ForEachVariable(tl, m_inlined.at(p), visit);
      continue;
    }
    auto* vd = dyn_cast<VarDecl>(dr->getDecl());
    if (!vd || (vd->hasGlobalStorage() && !vd->isStaticLocal())) continue;
    const bool isLoopVar = std::any_of(tl.loops.begin(), tl.loops.end(), [&](const LoopHeader& h) { return h.var == vd; });
    visit(dr, vd, isLoopVar || !StateBuffer(tl, vd).empty() || (tl.locals.count(vd) && !m_hostLoopVars.count(vd)));
  }
}

void ControlRewriter::CheckUniform(ThreadLoop& tl, const Expr* e, const std::string& where, bool readOnGpu) {
  ForEachVariable(tl, e, [&](const DeclRefExpr* dr, const VarDecl* vd, bool perThread) {
    if (perThread)
      Error(tl, dr->getBeginLoc(), "'" + vd->getNameAsString() + "' differs from thread to thread, but " + where + " in the thread loop of '" + m_ctrl.name +
            "' runs once for all threads in wavefront mode", "pass per-thread values to kernels by address (&" + vd->getNameAsString() + ") and branch inside the kernels");
    else if (readOnGpu && !tl.locals.count(vd) && std::find(tl.outer.begin(), tl.outer.end(), vd) == tl.outer.end())
      tl.outer.push_back(vd);
  });
}

bool ControlRewriter::TryRtvNest(const ForStmt* outer) {
  std::vector<LoopHeader> loops;
  const Stmt* cur = outer;
  while (auto* fs = dyn_cast_or_null<ForStmt>(cur)) {
    LoopHeader h;
    if (!LoopShapeProblem(m_c.ctx, fs, h).empty()) return false;
    loops.push_back(h);
    cur = SingleStatement(fs->getBody());
  }
  auto* expr = dyn_cast_or_null<Expr>(cur);
  auto* call = expr ? dyn_cast<CXXMemberCallExpr>(expr->IgnoreImplicit()) : nullptr;
  if (!call || !call->getMethodDecl() || !IsKernelName(call->getMethodDecl()->getName()) || IpvDims(call->getMethodDecl()->getName()))
    return false;
  auto* md = call->getMethodDecl();
  std::map<unsigned, const LoopHeader*> axes;
  for (unsigned i = 0; i < md->getNumParams() && i < call->getNumArgs(); ++i) {
    if (!IsThreadIdName(md->getParamDecl(i)->getName())) continue;
    auto* dr = dyn_cast<DeclRefExpr>(call->getArg(i)->IgnoreCasts()->IgnoreParens());  // uint32_t(i) is fine
    const LoopHeader* match = nullptr;
    for (auto& h : loops)
      if (dr && dr->getDecl() == h.var) match = &h;
    if (!match) {
      m_c.rep.Error(call->getArg(i)->getBeginLoc(), "thread id argument of '" + md->getNameAsString() + "' must be the variable of an enclosing loop",
                    "call it as: for (int i = 0; i < n; i++) " + md->getNameAsString() + "(i, ...);");
      return true;
    }
    axes[ThreadAxis(md->getParamDecl(i)->getName())] = match;
  }
  if (axes.size() < loops.size()) return false;  // outer loops are host loops: try the inner nest
  if (axes.size() != loops.size()) {
    m_c.rep.Error(outer->getBeginLoc(), "loops around '" + md->getNameAsString() + "' do not match its thread id parameters",
                  "use one loop per thread id parameter (tidX, tidY, ...), with nothing else in the loops");
    return true;
  }
  std::string counts;
  for (auto& [axis, h] : axes) {
    Expr::EvalResult r;
    if (!(h->start->EvaluateAsInt(r, m_c.ctx) && r.Val.getInt() == 0))
      m_c.rep.Error(h->start->getBeginLoc(), "loop around kernel '" + md->getNameAsString() + "' must start at 0",
                    "start at 0 and add the offset inside the kernel");
    counts += ", " + CountExpr(m_c, *h);
  }
  Note(call);
  if (m_c.model.forIspc && IspcRtvNest(outer, call, axes, loops.front(), loops.size())) return true;
  SourceLocation end = Lexer::findLocationAfterToken(outer->getEndLoc(), tok::semi, m_c.ctx.getSourceManager(), m_c.ctx.getLangOpts(), false);
  CharSourceRange range = end.isValid() ? CharSourceRange::getCharRange(outer->getBeginLoc(), end) : CharSourceRange::getTokenRange(outer->getSourceRange());
  m_gpu.ReplaceText(range, md->getNameAsString() + "Cmd(crt_cmd" + counts + Args(call, true) + ");");
  ParallelOnCpu(outer, loops.front(), loops.size());
  return true;
}

std::pair<std::string, std::string> ControlRewriter::ParallelChoiceAround(const ForStmt* outer, const LoopHeader& outermost, size_t nest,
                                                                          const std::string& way) {
  const unsigned col = m_c.ctx.getSourceManager().getExpansionColumnNumber(outer->getBeginLoc());
  const std::string indent(col > 0 ? col - 1 : 0, ' ');
  // Chunks of 16 threads; a nest's rows one at a time (its inner loops run whole in each).
  const ChunkedLoop chunked = ChunkLoop(m_cpu, m_c.ctx, outer, outermost, "crt_loop.parallel", nest > 1 ? "1" : "16");
  return {"{  // crossrt: on all cores, or on this thread while that has been faster\n" + indent + "static crossrt::ParallelChoice crt_choice;\n" + indent +
              "const auto crt_loop = crt_choice.Begin(" + CountExpr(m_c, outermost) + (way.empty() ? "" : ", " + way) + ");\n" + indent + chunked.head + "\n" + indent,
          "\n" + indent + chunked.tail + "\n" + indent + "crt_choice.End(crt_loop);\n" + indent + "}"};
}

void ControlRewriter::ParallelOnCpu(const ForStmt* outer, const LoopHeader& outermost, size_t nest) {
  const auto [before, after] = ParallelChoiceAround(outer, outermost, nest);
  m_cpu.InsertTextBefore(outer->getBeginLoc(), before);
  const SourceLocation semi = Lexer::findLocationAfterToken(outer->getEndLoc(), tok::semi, m_c.ctx.getSourceManager(), m_c.ctx.getLangOpts(), false);
  if (semi.isValid()) m_cpu.InsertTextAfter(semi, after);  // a body of one statement: after its ';'
  else m_cpu.InsertTextAfterToken(outer->getEndLoc(), after);
}

}  // namespace crossrt::engine
