// The bodies of thread loops that call several kernels: as the megakernel's GLSL (one shader runs the
// whole body per thread) and as the wavefront's host code (one dispatch per kernel call, the per-thread
// locals kept in buffers between them).

#include "generate/GeneratedNames.h"
#include "analyse/AnalysisContext.h"
#include "analyse/AstQueries.h"
#include "control/ControlFunctions.h"
#include "control/ControlRewriter.h"
#include "analyse/KernelParams.h"
#include "analyse/LoopShape.h"
#include "analyse/Naming.h"
#include "print/GlslTypes.h"
#include "print/ispc/IspcTypes.h"

#include <algorithm>
#include <regex>

using namespace clang;

namespace crossrt::engine {

// The initializer that starts an ISPC per-thread local at zero, as LiteMath's constructors do in C++
// (structs are left as GLSL leaves them).
static std::string IspcZero(const std::string& glslType) {
  if (glslType == "float" || glslType == "int" || glslType == "uint") return " = 0";
  static const std::regex vector(R"(^[iu]?vec[234]$)");
  if (std::regex_match(glslType, vector)) return " = make_" + IspcTypeName(glslType) + "(0)";
  if (glslType == "mat3") return " = make_float3x3_from_cols(make_float3(0), make_float3(0), make_float3(0))";
  if (glslType == "mat4") return " = make_float4x4_from_cols(make_float4(0), make_float4(0), make_float4(0), make_float4(0))";
  return "";
}

std::string ControlRewriter::ThreadBodyGlsl(ThreadLoop& tl, KernelPrinter& printer, const Stmt* s, int indent) {
  const std::string pad(2 * indent, ' ');
  if (auto* cs = dyn_cast<CompoundStmt>(s)) {
    std::string out;
    for (auto* child : cs->body()) out += ThreadBodyGlsl(tl, printer, child, indent);
    return out;
  }
  if (isa<NullStmt>(s)) return "";
  if (auto* ds = dyn_cast<DeclStmt>(s)) {
    std::string out;
    for (auto* d : ds->decls()) {
      auto* vd = dyn_cast<VarDecl>(d);
      if (!vd) continue;
      const Expr* init = vd->getInit();
      if (IsConstantLocal(vd)) {  // the same for every thread: a constant of the shader, and of the host code
        m_hostLoopVars.insert(vd);
        const std::string type = *GlslTypeOf(vd->getType().getUnqualifiedType());
        out += pad + "const " + (m_c.model.forIspc ? IspcTypeName(type) : type) + " " + KernelPrinter::SafeName(vd->getNameAsString()) + " = " +
               printer.Expr(init) + ";\n";
        continue;
      }
      auto* construct = init ? dyn_cast<CXXConstructExpr>(init->IgnoreImplicit()) : nullptr;
      const bool startsAtValue = init && !(construct && construct->getNumArgs() == 0);
      auto g = GlslTypeOf(vd->getType());
      if (!g || vd->getType()->isArrayType() || vd->getType()->isPointerType()) {
        Error(tl, vd->getLocation(), "per-thread local '" + vd->getNameAsString() + "' of type '" + vd->getType().getAsString(m_c.ctx.getPrintingPolicy()) +
              "' has no GPU equivalent", "use int, uint, float, LiteMath types or plain structs of those; keep arrays in a struct");
        continue;
      }
      tl.stateBuffers.push_back({vd, m_ctrl.name + (m_threadLoops > 1 ? std::to_string(m_threadLoops) : "") + "_" + vd->getNameAsString()});
      static const std::regex zeroable(R"(^(float|int|uint|[iu]?vec[234]|mat[234])$)");
      std::string name = KernelPrinter::SafeName(vd->getNameAsString());
      if (startsAtValue) {  // float v = 1.0f;: the megakernel sets it; the wavefront fills its buffer with the host's value
        static const std::regex scalar32(R"(^(float|int|uint)$)");
        if (IsUniform(tl, init) && !ContainsCall(init) && std::regex_match(*g, scalar32))
          tl.startValues[vd] = ResolvedText(init);
        else
          tl.megakernelOnly = true;  // a value per thread, a call's, or not one 32-bit word: computed by the thread itself
        out += pad + (m_c.model.forIspc ? IspcTypeName(*g) : *g) + " " + name + " = " + printer.Expr(init) + ";\n";
        continue;
      }
      if (m_c.model.forIspc) {  // LiteMath's types start at zero in C++ too
        out += pad + IspcTypeName(*g) + " " + name + IspcZero(*g) + ";\n";
        continue;
      }
      out += pad + *g + " " + name + (std::regex_match(*g, zeroable) ? " = " + *g + "(0)" : "") + ";\n";
    }
    return out;
  }
  if (auto* fs = dyn_cast<ForStmt>(s)) {
    auto* ds = dyn_cast_or_null<DeclStmt>(fs->getInit());
    auto* var = ds && ds->isSingleDecl() ? dyn_cast<VarDecl>(ds->getSingleDecl()) : nullptr;
    if (!var || !var->getInit() || !fs->getCond() || !fs->getInc()) {
      Error(tl, fs->getBeginLoc(), "a loop in the thread loop of '" + m_ctrl.name + "' must declare one counter and have a condition and a step",
            "write for (int i = 0; i < n; i++)");
      return "";
    }
    m_hostLoopVars.insert(var);
    CheckUniform(tl, var->getInit(), "the loop's start");
    CheckUniform(tl, fs->getCond(), "the loop's condition");
    CheckUniform(tl, fs->getInc(), "the loop's step");
    std::string header = "for (" + (m_c.model.forIspc ? IspcTypeName(*GlslTypeOf(var->getType())) : *GlslTypeOf(var->getType())) + " " + KernelPrinter::SafeName(var->getNameAsString()) + " = " + printer.Expr(var->getInit()) + "; " +
                         printer.Expr(fs->getCond()) + "; " + printer.Expr(fs->getInc()) + ")";
    m_hostLoopDepth++;
    const std::string loopBody = ThreadBodyGlsl(tl, printer, fs->getBody(), indent + 1);
    m_hostLoopDepth--;
    return pad + header + "\n" + pad + "{\n" + loopBody + pad + "}\n";
  }
  // `if (!kernel_X(...)) break;`: a kernel returning bool ends this thread's loop (kernel_slicer's
  // loop-break form). Threads leave at different times, which only the megakernel follows.
  if (auto* is = dyn_cast<IfStmt>(s)) {
    const Expr* cond = is->getCond()->IgnoreParenImpCasts();
    bool negated = false;
    if (auto* uo = dyn_cast<UnaryOperator>(cond); uo && uo->getOpcode() == UO_LNot) {
      negated = true;
      cond = uo->getSubExpr()->IgnoreParenImpCasts();
    }
    auto* kernelCall = dyn_cast<CXXMemberCallExpr>(cond);
    const Stmt* then = SingleStatement(is->getThen());
    // `if (mid == uint(-1)) break;`: a test of this thread's locals (no calls) may leave too.
    if (!kernelCall && then && !is->getElse() && !ContainsCall(is->getCond())) {
      auto* ret = dyn_cast<ReturnStmt>(then);
      const bool loopExit = (isa<BreakStmt>(then) || isa<ContinueStmt>(then)) && m_hostLoopDepth > 0;
      const bool threadExit = ret && !ret->getRetValue() && m_inlineDepth >= 0 && m_hostLoopDepth == m_inlineDepth;
      if (loopExit || threadExit) {
        tl.megakernelOnly = true;
        const std::string leave = threadExit ? (m_inlineDepth == 0 ? "return;\n" : "continue;  // return from " + m_perThread->getNameAsString() + "\n")
                                             : isa<BreakStmt>(then) ? "break;\n" : "continue;\n";
        return pad + "if (" + printer.Expr(is->getCond()) + ")\n" + pad + "  " + leave;
      }
    }
    const bool leaves = then && (isa<BreakStmt>(then) || isa<ContinueStmt>(then));
    // `if (!kernel_RayTrace(...)) return;` in the per-thread function, outside its own loops: this
    // thread's work ends (or, in a loop of passes around the call, this pass's).
    auto* ret = dyn_cast_or_null<ReturnStmt>(then);
    const bool returns = ret && !ret->getRetValue() && m_inlineDepth >= 0 && m_hostLoopDepth == m_inlineDepth;
    if (!kernelCall || !kernelCall->getMethodDecl() || !kernelCall->getMethodDecl()->getReturnType()->isBooleanType() || !(leaves || returns) ||
        is->getElse() || (m_hostLoopDepth == 0 && !returns)) {
      Error(tl, s->getBeginLoc(), "the thread loop of '" + m_ctrl.name + "' may branch only on a kernel's bool result, to leave a loop inside it",
            "write if (!kernel_X(tid, ...)) break; (or continue) in a counted loop of the thread loop, or return; at the top of the per-thread "
            "function, and branch on anything else inside the kernels");
      return "";
    }
    tl.megakernelOnly = true;
    const std::string leave = returns ? (m_inlineDepth == 0 ? "return;  // from " + m_perThread->getNameAsString() + ": this thread is done\n"
                                                            : "continue;  // return from " + m_perThread->getNameAsString() + ": this pass is done\n")
                                      : isa<BreakStmt>(then) ? "break;\n" : "continue;\n";
    return pad + "if (" + (negated ? "!" : "") + KernelCallGlsl(tl, printer, kernelCall) + ")\n" + pad + "  " + leave;
  }
  auto* call = dyn_cast<CXXMemberCallExpr>(s);
  auto* md = call ? call->getMethodDecl() : nullptr;
  if (IsPerThreadCall(md)) {  // kernel_slicer's pass loop around the per-thread function: its body here
    const int saved = m_inlineDepth;
    m_inlineDepth = m_hostLoopDepth;
    std::string out = ThreadBodyGlsl(tl, printer, m_perThread->getBody(), indent);
    m_inlineDepth = saved;
    return out;
  }
  if (!md || !IsKernelName(md->getName()) || IpvDims(md->getName()) || !isa<CXXThisExpr>(call->getImplicitObjectArgument()->IgnoreParenImpCasts())) {
    Error(tl, s->getBeginLoc(), "the thread loop of '" + m_ctrl.name + "' may hold only per-thread local declarations, kernel_ calls and counted loops around them",
          "move this code into a kernel: the loop's body runs once per thread, on the GPU");
    return "";
  }
  return pad + KernelCallGlsl(tl, printer, call) + ";\n";
}

bool ControlRewriter::IsUniform(const ThreadLoop& tl, const Expr* e) const {
  bool uniform = true;
  ForEachVariable(tl, e, [&](const DeclRefExpr*, const VarDecl*, bool perThread) { uniform = uniform && !perThread; });
  return uniform;
}

bool ControlRewriter::IsConstantLocal(const VarDecl* vd) const {
  Expr::EvalResult r;
  return vd->getInit() && vd->getType().isConstQualified() && vd->getType()->isArithmeticType() && GlslTypeOf(vd->getType().getUnqualifiedType()) &&
         vd->getInit()->EvaluateAsRValue(r, m_c.ctx);
}

bool ControlRewriter::IsPerThreadCall(const CXXMethodDecl* md) const {
  const FunctionDecl* def = nullptr;
  return m_perThread && md && md->hasBody(def) && def == m_perThread;
}

std::string ControlRewriter::KernelCallGlsl(ThreadLoop& tl, KernelPrinter& printer, const CXXMemberCallExpr* call) {
  auto* md = call->getMethodDecl();
  Note(call);
  auto& calls = tl.mega.megakernelCalls;
  if (std::find(calls.begin(), calls.end(), md->getNameAsString()) == calls.end()) calls.push_back(md->getNameAsString());
  std::string args = m_c.model.forIspc ? "self" : "", buffers;  // ISPC: the class data first, the buffers last (IspcRtvHead)
  std::set<unsigned> axes;
  for (unsigned i = 0; i < call->getNumArgs() && i < md->getNumParams(); ++i) {
    auto* p = md->getParamDecl(i);
    const Expr* arg = call->getArg(i);
    std::string a;
    if (IsThreadIdName(p->getName())) {
      auto* dr = dyn_cast<DeclRefExpr>(Resolve(arg)->IgnoreCasts()->IgnoreParens());
      auto* vd = dr ? dyn_cast<VarDecl>(dr->getDecl()) : nullptr;
      bool isLoopVar = vd && std::any_of(tl.loops.begin(), tl.loops.end(), [&](const LoopHeader& h) { return h.var == vd; });
      if (!isLoopVar) {
        Error(tl, arg->getBeginLoc(), "thread id argument of '" + md->getNameAsString() + "' must be a variable of the thread loop around it",
              "pass the loop variables themselves, e.g. " + md->getNameAsString() + "(x, y, ...)");
        continue;
      }
      const unsigned axis = ThreadAxis(p->getName());
      auto [it, inserted] = tl.axisOf.insert({vd, axis});
      if (!inserted && it->second != axis)
        Error(tl, arg->getBeginLoc(), "'" + vd->getNameAsString() + "' is passed as thread id " + p->getNameAsString() + " here, but as another axis elsewhere in the thread loop",
              "pass each loop variable as the same thread id (tidX, tidY, tidZ) to every kernel");
      axes.insert(axis);
      std::string type = GlslTypeOf(p->getType()).value_or("uint"), varType = GlslTypeOf(vd->getType()).value_or("int");
      std::string name = KernelPrinter::SafeName(vd->getNameAsString());
      a = type == varType ? name : m_c.model.forIspc ? "((" + IspcTypeName(type) + ")(" + name + "))" : type + "(" + name + ")";
    } else if (IsImageParam(p)) {
      Error(tl, arg->getBeginLoc(), "Image2D argument of '" + md->getNameAsString() + "' in a thread loop that calls several kernels",
            "the megakernel binds members only: make the image a member of the class, or give the kernel a thread loop of its own");
      continue;
    } else if (p->getType()->isPointerType()) {
      auto* vd = AddressedVar(arg);
      if (vd && !StateBuffer(tl, vd).empty()) {
        tl.passed.insert(vd);
        a = KernelPrinter::SafeName(vd->getNameAsString());
      } else if (vd) {
        Error(tl, arg->getBeginLoc(), "'&" + vd->getNameAsString() + "' passed to '" + md->getNameAsString() + "' is not a per-thread local declared in the thread loop",
              "declare the variable inside the thread loop's body");
        continue;
      } else {
        CheckNotThreadState(md, p, arg);
        CheckUniform(tl, arg, "a buffer argument", false);  // bound by the host
        const std::string bound = AddMegakernelBuffer(tl, md, p, BufferArg(Resolve(arg)), ResolvedText(arg), arg->getBeginLoc());
        if (!p->getType()->getPointeeType().isConstQualified()) WrittenThrough(Resolve(arg));
        buffers += ", " + (bound.empty() ? KernelParamName(md, i) : bound);
        continue;  // a global buffer of the megakernel, named as the kernel names it
      }
    } else {
      CheckUniform(tl, arg, "the by-value argument '" + p->getNameAsString() + "'");
      a = printer.Expr(Resolve(arg));
    }
    args += (args.empty() ? "" : ", ") + a;
  }
  if (axes.size() != tl.loops.size())
    Error(tl, call->getBeginLoc(), "'" + md->getNameAsString() + "' takes " + std::to_string(axes.size()) + " thread ids, but the thread loop around it has " +
          std::to_string(tl.loops.size()) + " loops", "give every kernel of a thread loop one thread id parameter (tidX, tidY, ...) per loop");
  return md->getNameAsString() + "(" + args + (m_c.model.forIspc ? buffers : "") + ")";
}

std::string ControlRewriter::KernelParamName(const CXXMethodDecl* md, unsigned i) const {
  for (auto& k : m_c.model.kernels)
    if (k.name == md->getNameAsString() && i < k.params.size()) return k.params[i].glslName;  // as the definition names it
  return KernelPrinter::SafeName(md->getParamDecl(i)->getNameAsString());
}

std::string ControlRewriter::AddMegakernelBuffer(ThreadLoop& tl, const CXXMethodDecl* md, const ParmVarDecl* p, const std::string& hostArg,
                                                 const std::string& cppArg, SourceLocation loc) {
  const KernelParam* kp = nullptr;
  for (auto& k : m_c.model.kernels)
    if (k.name == md->getNameAsString())
      for (auto& x : k.params)
        if (x.name == p->getNameAsString()) kp = &x;
  if (!kp) return "";  // the kernel failed analysis (reported there)
  std::string name = kp->glslName;
  for (unsigned i = 0; i < tl.mega.params.size(); ++i) {
    KernelParam& have = tl.mega.params[i];
    if (have.name != name) continue;
    if (tl.bufferArgs[i] == hostArg && have.glslType == kp->glslType) {
      have.isConstPointee = have.isConstPointee && kp->isConstPointee;
      return name;
    }
    // Two kernels' parameters of one name get different buffers (kernel_slicer's test 051).
    if (!m_c.model.forIspc) {  // GLSL: the megakernel binds each under the parameter's name, which its kernels' code reads
      if (tl.wavefrontOnly.empty()) {
        tl.wavefrontOnly = "parameter '" + p->getNameAsString() + "' of '" + md->getNameAsString() +
                           "' is given another buffer than a parameter of the same name of another kernel in the thread loop";
        tl.wavefrontOnlyAt = loc;
      }
      return "";
    }
    name = kp->glslName + "_" + md->getNameAsString();  // ISPC passes buffers to each kernel: another name for this one
    i = unsigned(-1);  // and look again
  }
  KernelParam b = *kp;
  b.name = name;
  b.glslName = name;
  tl.mega.params.push_back(b);
  tl.bufferArgs.push_back(hostArg);
  tl.cppBufferArgs.push_back(cppArg);
  tl.hostArgs += ", " + hostArg;
  return name;
}

std::string ControlRewriter::ThreadBodyCpp(ThreadLoop& tl, const Stmt* s) {
  if (auto* cs = dyn_cast<CompoundStmt>(s)) {
    std::string out;
    for (auto* child : cs->body()) out += ThreadBodyCpp(tl, child);
    return out;
  }
  if (auto* fs = dyn_cast<ForStmt>(s)) {
    // A host loop of a per-thread function runs in the control function: its parameters there are
    // what the control function passes (StupidPathTrace(i, 6, ...) reads 6 for a_maxDepth).
    struct Refs : RecursiveASTVisitor<Refs> {
      std::vector<const DeclRefExpr*> found;
      bool VisitDeclRefExpr(DeclRefExpr* dr) { found.push_back(dr); return true; }
    } refs;
    for (const Stmt* part : {fs->getInit(), static_cast<const Stmt*>(fs->getCond()), static_cast<const Stmt*>(fs->getInc())})
      if (part) refs.TraverseStmt(const_cast<Stmt*>(part));
    auto& sm = m_c.ctx.getSourceManager();
    const SourceLocation begin = fs->getBeginLoc();
    std::string header = m_c.Text(SourceRange(begin, fs->getRParenLoc()));
    std::sort(refs.found.begin(), refs.found.end(), [&](const DeclRefExpr* a, const DeclRefExpr* b) {
      return sm.getFileOffset(a->getBeginLoc()) > sm.getFileOffset(b->getBeginLoc());  // last first: earlier offsets stay valid
    });
    for (auto* dr : refs.found)
      if (auto* p = dyn_cast<ParmVarDecl>(dr->getDecl()); p && m_inlined.count(p) && ResolvedText(dr) != p->getNameAsString()) {
        const unsigned at = sm.getFileOffset(dr->getBeginLoc()) - sm.getFileOffset(begin);
        if (sm.getFileID(dr->getBeginLoc()) != sm.getFileID(begin) || at + p->getName().size() > header.size()) {
          Error(tl, dr->getBeginLoc(), "a loop of '" + cast<FunctionDecl>(p->getDeclContext())->getNameAsString() + "' reads its parameter '" +
                p->getNameAsString() + "' through a macro", "write the loop's header without macros");
          continue;
        }
        header.replace(at, p->getName().size(), "(" + ResolvedText(dr) + ")");
      }
    return header + "\n{\n" + ThreadBodyCpp(tl, fs->getBody()) + "}\n";
  }
  if (auto* ds = dyn_cast<DeclStmt>(s)) {  // constants as written (the other locals' buffers are set up before)
    std::string out;
    for (auto* d : ds->decls())
      if (auto* vd = dyn_cast<VarDecl>(d); vd && IsConstantLocal(vd))
        out += "const " + CppTypeName(m_c.ctx, vd->getType().getUnqualifiedType()) + " " + vd->getNameAsString() + " = " + ResolvedText(vd->getInit()) + ";\n";
    return out;
  }
  if (isa<IfStmt>(s)) return "";  // a loop a kernel's result may end: the megakernel only
  auto* call = dyn_cast<CXXMemberCallExpr>(s);
  auto* md = call ? call->getMethodDecl() : nullptr;
  if (IsPerThreadCall(md)) return ThreadBodyCpp(tl, m_perThread->getBody());
  if (!md || !IsKernelName(md->getName())) return "";  // declarations (their buffers are set up before), or reported
  std::string args;
  for (unsigned i = 0; i < call->getNumArgs() && i < md->getNumParams(); ++i) {
    auto* p = md->getParamDecl(i);
    const Expr* arg = call->getArg(i);
    if (IsThreadIdName(p->getName()) || isa<CXXDefaultArgExpr>(arg)) continue;
    if (!p->getType()->isPointerType()) {
      args += ", " + ResolvedText(arg);
      continue;
    }
    auto* vd = AddressedVar(arg);
    std::string buffer = vd ? StateBuffer(tl, vd) : "";
    args += ", " + (buffer.empty() ? BufferArg(Resolve(arg)) : generated::kThreadState + "." + buffer + ".View()");
  }
  return md->getNameAsString() + "Cmd(crt_cmd" + tl.counts + args + ");\n";
}

}  // namespace crossrt::engine
