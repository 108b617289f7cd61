// One kernel from start to end: its loop nest, parameters, writes and reductions, the GLSL of its body
// through the printer, and the CPU copy whose outer loop runs in chunks on all cores. Takes a
// kernel's method; adds a Kernel to the model.
#include "analyse/Kernels.h"

#include "analyse/AnalysisContext.h"
#include "analyse/AstQueries.h"
#include "analyse/CpuCopies.h"
#include "analyse/KernelParams.h"
#include "analyse/LoopShape.h"
#include "analyse/Members.h"
#include "analyse/Naming.h"
#include "analyse/Shadowing.h"
#include "analyse/VirtualCalls.h"
#include "analyse/WriteVisitor.h"
#include "analyse/Writes.h"
#include "generate/GeneratedNames.h"
#include "print/ispc/IspcTypes.h"
#include "print/Printers.h"

#include <algorithm>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

// The most bytes of an array whose elements one kernel reduces on the GPU (float coefs[64], float3
// coefs[16]): each thread holds them, and each workgroup 64 copies in shared memory (templates/glsl/
// kernel.comp), up to 16 KiB. Past that, an error at `at` (the first reduction of a member's elements).
constexpr unsigned kMaxReducedArrayBytes = 256;
static void CheckReducedArraySize(Context& c, const Kernel& k, const Reduction& r, SourceLocation at) {
  const auto [base, dims] = SplitArray(r.glslType);
  if (dims.empty() || c.model.forIspc) return;
  const unsigned count = unsigned(std::stoul(dims.substr(1))), bytes = count * Std430VectorStride(base);
  if (bytes > kMaxReducedArrayBytes)
    c.rep.GpuError(at, "kernel '" + k.name + "' reduces the " + std::to_string(count) + " elements of " + (r.local ? "local" : "member") + " array '" +
                           r.member + "' (" + std::to_string(bytes) + " bytes; a GPU thread holds at most " + std::to_string(kMaxReducedArrayBytes) + ")",
                   "count into a std::vector member with LiteMath's InterlockedAdd (atomics), or reduce fewer elements per kernel");
}

// A reduction's type: GLSL's, or on ISPC also double (a sum of doubles stays double there).
static std::string ReductionType(Context& c, QualType t) {
  if (c.model.forIspc && t.getCanonicalType()->isSpecificBuiltinType(BuiltinType::Double)) return "double";
  return GlslTypeOf(t).value_or("float");
}

// The ISPC thread function's parameters after the thread ids (varying): the class's data, the
// kernel's arguments (uniform: one value, or one array, for all lanes) and each reduction's
// per-lane accumulator, by reference.
static std::string IspcThreadHead(Context& c, const Kernel& k, const std::vector<std::pair<std::string, std::string>>& threadIds, const FunctionDecl* def) {
  // Not inline here: inlined into its export function, LBVH's Karras12 (a varying early return in a
  // helper it calls in a loop) crashed on the deepest tree test_lbvh builds (ISPC 1.28.2, avx512skx).
  // AnalyzeKernel inlines the bodies that call no functions of the user's (IspcInlineBody).
  std::string head = "static void " + k.name + "(uniform " + c.cls->getNameAsString() + "_Data *uniform self";
  // The innermost loop's variable runs across the lanes; the outer loops' are the gang's (in tiles,
  // both run across the lanes).
  for (size_t i = 0; i < threadIds.size(); ++i)
    head += ", " + std::string(i && !k.ispcTiled ? "uniform " : "") + threadIds[i].first + " " + threadIds[i].second;
  for (unsigned i = 0; i < k.params.size(); ++i) {
    const KernelParam& p = k.params[i];
    if (p.isImage) {  // LiteMath.isph's view of the C++ image
      head += ", const uniform crt_Image_" + IspcTypeName(p.glslType) + " &" + p.glslName;
      continue;
    }
    const auto [base, dims] = SplitArray(IspcTypeName(p.glslType));
    if (p.isPointer) head += std::string(", ") + (p.isConstPointee ? "const " : "") + "uniform " + base + " *uniform " + p.glslName;
    else head += ", uniform " + base + " " + p.glslName + dims;
  }
  for (auto& r : k.reductions) {  // a member array's elements: the lane's array (ISPC passes it by pointer)
    const auto [base, dims] = SplitArray(IspcTypeName(r.glslType));
    head += ", " + base + (dims.empty() ? " &" : " ") + generated::ReductionLocal(r.member) + dims;
  }
  return head + ")";
}

// The ISPC thread function of a kernel_ function, which a thread loop's ISPC body calls: the class
// data, then as GLSL's (the thread ids, the per-thread values, by reference where written, and the
// by-value arguments, all per lane), then the buffers and images GLSL binds, as ISPC pointers.
static std::string IspcRtvHead(Context& c, const Kernel& k, const std::vector<std::pair<std::string, std::string>>& threadParams) {
  std::string head = std::string("static ") + (k.returnsBool ? "bool " : "void ") + k.name + "(uniform " + c.cls->getNameAsString() + "_Data *uniform self";
  for (auto [type, name] : threadParams) {
    const bool inout = type.rfind("inout ", 0) == 0;
    if (inout) type = type.substr(6);
    head += ", " + IspcTypeName(type) + (inout ? " &" : " ") + name;
  }
  for (const KernelParam& p : k.params) {
    if (p.isImage) head += ", const uniform crt_Image_" + IspcTypeName(p.glslType) + " &" + p.glslName;
    else if (p.isPointer && !p.threadState)
      head += std::string(", ") + (p.isConstPointee ? "const " : "") + "uniform " + SplitArray(IspcTypeName(p.glslType)).first + " *uniform " + p.glslName;
  }
  return head + ")";
}

// Whether s, or a method of cls it calls, calls through a member pointer to a polymorphic class
// (m_pAccelStruct->RayQuery_NearestHit): on ISPC such iterations branch per lane, and a tile of
// neighbouring pixels keeps the lanes on the same path longer than a row does. With 16 lanes on
// 2 threads, PrimaryRays_ISPC rendered the dragon (1024x1024, 4 occlusion rays a pixel) at 0.80x of
// _CPU's speed in rows and 0.87x in tiles; its primary rays alone, read in that order, traced at
// 0.76-0.78x of Embree's rtcIntersect1 in rows and 0.86-0.91x in 4x4 tiles.
static bool CallsComposedCode(const Stmt* s, const CXXRecordDecl* cls, std::set<const FunctionDecl*>& seen) {
  struct Finder : RecursiveASTVisitor<Finder> {
    const CXXRecordDecl* cls; std::set<const FunctionDecl*>& seen; bool found = false;
    Finder(const CXXRecordDecl* c, std::set<const FunctionDecl*>& sn) : cls(c), seen(sn) {}
    bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
      const clang::Expr* obj = call->getImplicitObjectArgument()->IgnoreParenImpCasts();
      if (auto* op = dyn_cast<CXXOperatorCallExpr>(obj); op && op->getOperator() == OO_Arrow) obj = op->getArg(0)->IgnoreParenImpCasts();
      if (auto* f = ThisField(obj); f && PolymorphicPointee(f->getType())) found = true;
      else if (auto* def = ThisMethodDef(call, cls); def && seen.insert(def).second) found = CallsComposedCode(def->getBody(), cls, seen);
      return !found;
    }
  } finder(cls, seen);
  finder.TraverseStmt(const_cast<Stmt*>(s));
  return finder.found;
}

// An ISPC thread function that calls no functions of the user's (no helpers, virtual or composed
// calls) is inlined into its export function, which then runs it with all lanes on in full gangs:
// called, it got the execution mask as an argument, and ran every load masked and every uniform
// branch as a varying one. Bloom_ISPC went from 1.74x to 2.1-2.4x of Bloom_CPU's speed.
static void IspcInlineBody(Kernel& k, const KernelPrinter& printer) {
  const auto& uses = printer.Uses();
  if (!uses.helpers.empty() || !uses.virtualCalls.empty() || !uses.composedCalls.empty()) return;
  const std::string plain = "\nstatic void " + k.name + "(";
  if (const size_t at = k.glslBody.find(plain); at != std::string::npos) k.glslBody.replace(at + 1, 7, "static inline ");
}

void AnalyzeKernel(Context& c, const CXXMethodDecl* md, const FunctionDecl* def) {
  Kernel k;
  k.name = md->getNameAsString();
  k.dims = IpvDims(k.name);
  k.rtv = k.dims == 0;
  k.sourceFile = BaseName(FileOf(c.ctx, def->getLocation()));
  k.definedAt = PlaceOf(c.ctx, def->getLocation());
  Reporter::ReachedFrom reachedFrom(c.rep, def->getLocation(), "kernel '" + k.name + "'", def->getSourceRange());
  // A kernel_ function may return bool, for its thread loop to leave a loop: if (!kernel_X(...)) break;
  k.returnsBool = k.rtv && md->getReturnType()->isBooleanType();
  if (!md->getReturnType()->isVoidType() && !k.returnsBool) {
    c.rep.Error(md->getLocation(), "kernel '" + k.name + "' returns a value",
                k.rtv ? "kernels return void, or bool for their thread loop to leave a loop (if (!" + k.name + "(...)) break;); write other results to pointer parameters"
                      : "kernels return void and write results to pointer parameters or members");
    return;
  }
  // The definition's parameter names: its body uses them (a declaration may name them otherwise).
  CheckKernelParams(c, md, def, k);
  for (unsigned i = 0; i < def->getNumParams(); ++i) {
    k.cppParamsDecl += (i ? ", " : "") + ParamDecl(c.ctx, md->getParamDecl(i), def->getParamDecl(i), i);
    const std::string name = def->getParamDecl(i)->getNameAsString(), declared = md->getParamDecl(i)->getNameAsString();
    k.cppArgs += (i ? ", " : "") + (!name.empty() ? name : !declared.empty() ? declared : "a_unnamed" + std::to_string(i));
  }
  std::unique_ptr<KernelPrinter> kernelPrinter = MakePrinter(c.model, c.ctx, c.cls, c.rep);
  KernelPrinter& printer = *kernelPrinter;
  // The ISPC class runs kernelND_ loop nests as ISPC, and kernel_ functions as the thread functions
  // its thread loops' ISPC bodies call (ThreadLoops.cpp).
  printer.compositions = c.compositions;
  printer.threadReturnsValue = k.returnsBool;
  for (auto& s : ClassStructNames(c.model)) printer.predeclaredStructs.insert(s);
  // Structs the parameters hold (buffers, push constants) are declared even when the body names no variable of them.
  for (auto* p : def->parameters()) {
    if (p->getType()->isPointerType()) printer.Type(p->getType()->getPointeeType(), p->getLocation());
    else if (auto* rd = p->getType().getNonReferenceType()->getAsCXXRecordDecl(); rd && !IsLiteMathType(p->getType().getNonReferenceType()) &&
             !IsImage2D(p->getType()) && GlslTypeOf(p->getType()))
      printer.Type(p->getType().getNonReferenceType(), p->getLocation());
    if (IsImageParam(p)) printer.imageParams.insert(p);
  }
  auto* body = dyn_cast<CompoundStmt>(def->getBody());
  if (!body) {
    c.rep.GpuError(md->getLocation(), "kernel '" + k.name + "' has a function-try-block", "GPU code has no exceptions: remove the try/catch");
    return;
  }
  std::vector<const Stmt*> preamble;      // declarations before the loop nest: every thread evaluates them
  std::vector<const Stmt*> before, after;  // all statements before and after the loop nest: one thread runs them
  const Stmt* threadBody = body;
  std::vector<const VarDecl*> outerVars;  // the loop nest's variables, outermost first
  std::vector<std::pair<std::string, std::string>> threadParams;  // (glsl type, name)

  if (k.rtv) {
    // The thread function takes the thread ids, the per-thread values and the by-value arguments,
    // so that a megakernel can call it as well as this kernel's own main().
    for (unsigned i = 0; i < k.params.size(); ++i) {
      const KernelParam& p = k.params[i];
      if (p.isThreadId) {
        k.dims = std::max(k.dims, ThreadAxis(p.name) + 1);
        k.threadAxes.push_back(ThreadAxis(p.name));
      }
      if (p.threadState) printer.valueParams.insert(def->getParamDecl(i));  // the body refers to the definition's
      if ((p.isPointer && !p.threadState) || p.isImage) continue;
      auto [base, dims] = SplitArray(p.glslType);
      std::string qualifier = p.threadState && !p.isConstPointee ? "inout " : "";
      threadParams.push_back({qualifier + base, p.glslName + dims});
    }
    if (k.dims == 0) {
      c.rep.Error(md->getLocation(), "kernel '" + k.name + "' has no thread id parameter",
                  "name the thread index parameter 'tid' (or tidX, tidY, tidZ), or name the kernel kernel1D_/kernel2D_ with loops inside");
      return;
    }
  } else {
    // kernelND_: optional declarations, then N perfectly nested loops.
    // [statements before] N perfectly nested loops [statements after]: the body's first for loop
    // to a bound that is not a constant is the nest (KernelLoopNest); what comes before and after
    // it (the paper's loop_start and loop_end) runs on one thread. The declarations before it are
    // also evaluated by every thread.
    const ForStmt* outer = KernelLoopNest(c.ctx, body);
    bool past = false;
    for (auto* s : body->body()) {
      if (isa<NullStmt>(s) || s == outer) past |= s == outer;
      else (past ? after : before).push_back(s);
    }
    if (!outer) {
      c.rep.Error(md->getLocation(), "kernel '" + k.name + "' has no loop", "a kernel" + std::to_string(k.dims) + "D_ function holds " + std::to_string(k.dims) + " nested for loops whose iterations become GPU threads");
      return;
    }
    const Stmt* cur = outer;
    std::vector<LoopHeader> headers;
    for (unsigned d = 0; d < k.dims; ++d) {
      auto* fs = dyn_cast<ForStmt>(cur);
      if (!fs) {
        c.rep.Error(cur->getBeginLoc(), "kernel '" + k.name + "' needs " + std::to_string(k.dims) + " perfectly nested loops",
                    "put nothing between the loop headers; move per-row code into the innermost body");
        return;
      }
      LoopHeader h;
      if (!ParseLoop(c, fs, h, k.name)) return;
      headers.push_back(h);
      outerVars.push_back(h.var);
      // `i < m_v.size()` of a vector that kernels append to: its size is only known on the GPU.
      if (auto* mc = dyn_cast<CXXMemberCallExpr>(h.end->IgnoreParenCasts()); mc && mc->getMethodDecl() && mc->getMethodDecl()->getName() == "size")
        if (auto* f = ThisField(mc->getImplicitObjectArgument()); f && c.appended.count(f->getNameAsString())) {
          Expr::EvalResult r;
          const std::string v = f->getNameAsString();
          if (k.dims != 1)
            c.rep.GpuError(h.end->getBeginLoc(), "kernel '" + k.name + "' loops to the size of '" + v + "', which kernels append to on the GPU, in a " +
                        std::to_string(k.dims) + "D loop nest", "loop to " + v + ".size() in a kernel1D_ kernel: it is dispatched indirectly, with the count the GPU computed");
          else if (!(h.start->EvaluateAsInt(r, c.ctx) && r.Val.getInt() == 0) || h.inclusive)
            c.rep.GpuError(h.end->getBeginLoc(), "kernel '" + k.name + "' loops over '" + v + "', which kernels append to on the GPU, but not from 0 to " + v + ".size()",
                        "write 'for (uint32_t i = 0; i < " + v + ".size(); ++i)' and skip elements inside the loop");
          else
            k.indirectVector = v;
          if (auto* m = FindMember(c.model, v)) m->usedByKernels = true;
        }
      Loop loop;
      loop.var = h.var->getNameAsString();
      loop.glslType = GlslTypeOf(h.var->getType()).value_or("int");
      loop.startCpp = c.Text(h.start->getSourceRange());
      loop.countCpp = CountExpr(c, h);
      k.loops.push_back(loop);
      threadParams.push_back({loop.glslType, KernelPrinter::SafeName(loop.var)});
      cur = fs->getBody();
      if (d + 1 < k.dims)
        if (auto* cs = dyn_cast<CompoundStmt>(cur); cs && cs->size() == 1) cur = cs->body_front();
    }
    threadBody = cur;
    // Thread ids are listed innermost first (x), like the dispatch.
    std::reverse(threadParams.begin(), threadParams.end());
    for (unsigned d = 0; d < k.dims; ++d) k.threadAxes.push_back(d);
  }

  // The locals declared before the nest, and the statements that only set them: every thread
  // evaluates them for itself, in order. (The locals the nest reduces are found first: a thread
  // starts those from the identity, and statements before the nest may not set them.)
  std::set<const VarDecl*> beforeLocals;
  for (auto* s : before)
    if (auto* ds = dyn_cast<DeclStmt>(s))
      for (auto* d : ds->decls())
        if (auto* vd = dyn_cast<VarDecl>(d)) beforeLocals.insert(vd);
  LocalReductionScanner localReductions(c, beforeLocals);
  localReductions.TraverseStmt(const_cast<Stmt*>(threadBody));
  std::set<const VarDecl*> reducedLocals;
  for (auto& [vd, op] : localReductions.reductions) reducedLocals.insert(vd);
  const std::set<const Stmt*> settingLocals = StatementsSettingLocals(before, reducedLocals);
  for (auto* s : before)
    if (isa<DeclStmt>(s) || settingLocals.count(s)) preamble.push_back(s);

  // ISPC: what every lane of a gang shares (IspcUniform.cpp): the kernel's scalar parameters, and
  // the outer loops' variables of a 2D or 3D nest, except where a 2D nest runs in tiles.
  if (c.model.forIspc && !k.rtv) {  // (a kernel_ function's arguments may differ per lane)
    for (unsigned i = 0; i < k.params.size() && i < def->getNumParams(); ++i)
      if (!k.params[i].isPointer && !k.params[i].isImage && !k.params[i].isThreadId && def->getParamDecl(i)->getType()->isArithmeticType())
        printer.uniformValues.insert(def->getParamDecl(i));
    std::set<const FunctionDecl*> seen;
    k.ispcTiled = !k.rtv && outerVars.size() == 2 && CallsComposedCode(threadBody, md->getParent(), seen);
    for (size_t d = 0; d + 1 < outerVars.size() && !k.ispcTiled; ++d) printer.uniformValues.insert(outerVars[d]);
  }

  // Reductions and member writes.
  WriteScanner ws(c);
  ws.TraverseStmt(const_cast<Stmt*>(threadBody));
  for (auto* s : preamble) ws.TraverseStmt(const_cast<Stmt*>(s));
  WriteScanner ends(c);  // the statements around the loop nest, which one thread runs
  ends.singleThread = true;
  for (auto* list : {&before, &after})
    for (auto* s : *list)
      if (!isa<DeclStmt>(s) && !settingLocals.count(s)) ends.TraverseStmt(const_cast<Stmt*>(s));
  if (!CheckLoopEnds(c, k.name, before, after, threadBody, localReductions.targets, settingLocals)) return;
  LocalReductionReads(c, k.name, localReductions, threadBody);
  ReductionReadScanner rs(c, ws);
  rs.TraverseStmt(const_cast<Stmt*>(threadBody));
  for (auto& [field, values] : ws.constantStores) {
    if (values.size() > 1 || ws.reductions.count(field))
      c.rep.Error(field->getLocation(), "the threads of kernel '" + k.name + "' set member '" + field->getNameAsString() +
                  "' to " + (values.size() > 1 ? "different values" : "a value and reduce it") + ": the result would depend on which thread comes last",
                  "set it to one constant (a flag), or reduce it (m = std::max(m, x))");
    struct Reads : RecursiveASTVisitor<Reads> {
      const FieldDecl* f; const std::set<const MemberExpr*>& stores; std::vector<SourceLocation> found;
      Reads(const FieldDecl* ff, const std::set<const MemberExpr*>& st) : f(ff), stores(st) {}
      bool VisitMemberExpr(MemberExpr* me) {
        if (me->getMemberDecl() == f && !stores.count(me)) found.push_back(me->getExprLoc());
        return true;
      }
    } reads(field, ws.constantStoreUses);
    reads.TraverseStmt(const_cast<Stmt*>(threadBody));
    for (auto loc : reads.found)
      c.rep.Error(loc, "kernel '" + k.name + "' reads '" + field->getNameAsString() + "', which its threads set",
                  "read it after the loop nest, or in the control function after the kernel");
    if (auto* m = FindMember(c.model, field->getNameAsString())) m->writtenByKernels = true;
  }
  // Reduced locals, in declaration order: a thread's part is <local>Local, as a member's is.
  std::set<const Stmt*> reductionDecls;  // their declarations, which the threads do not evaluate
  for (auto* s : preamble)
    for (auto* d : isa<DeclStmt>(s) ? cast<DeclStmt>(s)->decls() : DeclStmt::decl_range(nullptr, nullptr)) {
      auto* vd = dyn_cast<VarDecl>(d);
      auto found = vd ? localReductions.reductions.find(vd) : localReductions.reductions.end();
      if (found == localReductions.reductions.end()) continue;
      if (!cast<DeclStmt>(s)->isSingleDecl()) {
        c.rep.Error(vd->getLocation(), "'" + vd->getNameAsString() + "', which the loop of kernel '" + k.name + "' reduces, is declared with other variables",
                    "declare it on its own: float " + vd->getNameAsString() + " = ...;");
        continue;
      }
      reductionDecls.insert(s);
      Reduction r;
      r.member = vd->getNameAsString();
      r.op = found->second;
      r.glslType = ReductionType(c, vd->getType());
      r.identity = Identity(r.op, SplitArray(r.glslType).first);  // of one element, for an array's elements
      r.local = true;
      QualType element = vd->getType();  // an array's (float bins[4]; bins[b] += x): its element's
      if (auto* arr = dyn_cast<ConstantArrayType>(element.getCanonicalType().getTypePtr())) element = arr->getElementType();
      r.cppType = element.getUnqualifiedType().getAsString(c.ctx.getPrintingPolicy());
      CheckReducedArraySize(c, k, r, vd->getLocation());
      printer.renames[vd] = generated::ReductionLocal(r.member);
      k.reductions.push_back(r);
    }
  if (k.rtv && !ws.reductions.empty()) {
    c.rep.Error(md->getLocation(), "member reductions are supported in kernel1D_/2D_/3D_ loops, not in '" + k.name + "'",
                "write the loop inside the kernel (kernel1D_" + k.name.substr(std::string("kernel_").size()) + ") so the translator sees the whole reduction");
    return;
  }
  if (!k.indirectVector.empty() && !ws.reductions.empty())
    c.rep.GpuError(md->getLocation(), "kernel '" + k.name + "' reduces members and is dispatched indirectly (it loops to " + k.indirectVector + ".size())",
                "reduce in a kernel with a count the host knows, or append the values and reduce them in a later kernel");
  // In declaration order, so that regeneration is stable.
  for (auto* field : ClassFields(c.cls)) {
    auto found = ws.reductions.find(field);
    if (found == ws.reductions.end()) continue;
    ReduceOp op = found->second;
    Reduction r;
    r.member = field->getNameAsString();
    r.op = op;
    r.glslType = ReductionType(c, field->getType());
    r.identity = Identity(op, SplitArray(r.glslType).first);  // of one element, for a member array's elements
    CheckReducedArraySize(c, k, r, ws.reductionSites.count(field) ? ws.reductionSites.at(field) : field->getLocation());
    printer.renames[field] = generated::ReductionLocal(r.member);
    k.reductions.push_back(r);
  }
  // After printing, the printer knows the helpers the kernel reaches: their writes count too.
  auto markVectorWrites = [&](const WriteScanner& scanner) {
    for (auto* set : {&scanner.vectorWrites, &scanner.atomicMembers, &scanner.memberWrites})
      for (auto* f : *set)
        if (auto* m = FindMember(c.model, f->getNameAsString())) m->writtenByKernels = true;
  };
  markVectorWrites(ws);
  markVectorWrites(ends);
  // A CRT_SPECIALIZE member is a constant of the GPU's pipelines: kernels only read it.
  struct SpecializedWrites : WriteVisitor<SpecializedWrites> {
    std::vector<std::pair<const FieldDecl*, SourceLocation>> found;
    void Written(const Expr* target, SourceLocation loc) {
      if (auto* f = RootField(target); f && IsSpecializedMember(f)) found.push_back({f, loc});
    }
    bool VisitCallExpr(CallExpr* call) {  // atomics, and helpers' non-const reference parameters (GLSL inout)
      const FunctionDecl* fd = call->getDirectCallee();
      if (IsCrossrtAtomic(fd) && call->getNumArgs() > 0) Written(call->getArg(0), call->getExprLoc());
      ReferenceArguments(call);
      return true;
    }
  } specializedWrites;
  specializedWrites.TraverseStmt(def->getBody());
  for (auto& [f, loc] : specializedWrites.found)
    c.rep.RecordingError(loc, "kernel '" + k.name + "' writes member '" + f->getNameAsString() +
                         "', which is CRT_SPECIALIZE: the GPU compiles the kernel's pipeline for the value it holds",
                         "set it on the host before calling the control function, or drop CRT_SPECIALIZE");
  for (auto& [field, loc] : ends.appends) ws.appends.emplace(field, loc);

  // GLSL: the thread function. ISPC: the same, its uniform arguments passed in (IspcThreadHead).
  std::ostringstream os;
  os << "// from " << c.cls->getNameAsString() << "::" << k.name << " (" << k.sourceFile << ")\n";
  if (c.model.forIspc && k.rtv) {
    os << IspcRtvHead(c, k, threadParams);
  } else if (c.model.forIspc) {
    for (auto& [type, name] : threadParams) type = IspcTypeName(type);
    os << IspcThreadHead(c, k, threadParams, def);
  } else {
    os << (k.returnsBool ? "bool " : "void ") << k.name << "(";
    for (size_t i = 0; i < threadParams.size(); ++i) os << (i ? ", " : "") << threadParams[i].first << " " << threadParams[i].second;
    os << ")";
  }
  os << "\n{\n";
  for (auto* s : preamble)
    if (!reductionDecls.count(s)) os << printer.Stmt(s, 1);
  if (auto* cs = dyn_cast<CompoundStmt>(threadBody))
    for (auto* s : cs->body()) os << printer.ThreadBody(s, 1, !k.rtv);
  else
    os << printer.ThreadBody(threadBody, 1, !k.rtv);
  os << "}\n";
  k.glslBody = os.str();
  if (c.model.forIspc) IspcInlineBody(k, printer);
  // The statements around the loop nest, as functions one thread runs before and after the others.
  // (The ISPC class runs them on the host, as the CPU class does.)
  // (Statements that only set locals need no thread of their own: every thread evaluated them.)
  const bool startRuns = std::any_of(before.begin(), before.end(), [&](const Stmt* s) { return !isa<DeclStmt>(s) && !settingLocals.count(s); });
  if (!c.model.forIspc && (startRuns || !after.empty())) {
    const auto sizeReadsInLoop = printer.Uses().sizeReads;  // after the loop a vector's final size is known
    const auto renames = printer.renames;
    for (auto& r : k.reductions)
      for (auto* f : ClassFields(c.cls))
        if (f->getNameAsString() == r.member) printer.renames.erase(f);  // the member itself, not a thread's part
    for (auto& [vd, op] : localReductions.reductions) printer.renames.erase(vd);
    printer.singleThread = true;
    const std::string from = "// from " + c.cls->getNameAsString() + "::" + k.name + " (" + k.sourceFile + "): ";
    if (startRuns) {
      k.glslStart = from + "the statements before its loop nest, run by one thread before the others\nvoid " + k.name + "_Start()\n{\n";
      for (auto* s : before) k.glslStart += printer.Stmt(s, 1);
      k.glslStart += "}\n";
    }
    if (!after.empty()) {
      k.glslFinish = from + "the statements after its loop nest, run by one thread after the others\nvoid " + k.name + "_Finish()\n{\n";
      for (auto* s : preamble) k.glslFinish += printer.Stmt(s, 1);
      // The reduced locals: their initial values and the threads' total (<kernel>_Reduce left it
      // in element 0 of the partials; when the nest had no threads there is none).
      std::string anyThreads;
      for (unsigned a = 0; a < k.dims; ++a) anyThreads += std::string(a ? " && " : "") + "crt_count" + "XYZ"[a] + " != 0u";
      for (auto& r : k.reductions)
        if (r.local) {
          // An array's elements (bins[b] += x): the totals of its elements in elements 0... of the partials.
          const std::string elements = SplitArray(r.glslType).second, at = elements.empty() ? "" : "[crt_e]";
          const std::string total = generated::ReductionPartials(r.member) + (elements.empty() ? "[0]" : "[crt_e]"), mine = r.member + at;
          const std::string combined = r.op == ReduceOp::Min ? "min(" + mine + ", " + total + ")"
                                       : r.op == ReduceOp::Max ? "max(" + mine + ", " + total + ")" : mine + " + " + total;
          if (elements.empty())
            k.glslFinish += "  if (" + anyThreads + ")\n    " + mine + " = " + combined + ";  // the threads' total\n";
          else
            k.glslFinish += "  if (" + anyThreads + ")  // the threads' totals\n    for (int crt_e = 0; crt_e < " + elements.substr(1, elements.size() - 2) +
                            "; ++crt_e)\n      " + mine + " = " + combined + ";\n";
        }
      for (auto* s : after) k.glslFinish += printer.Stmt(s, 1);
      k.glslFinish += "}\n";
    }
    printer.singleThread = false;
    printer.renames = renames;
    for (auto* f : printer.Uses().emptiedVectors)
      if (!c.appended.count(f->getNameAsString()))
        c.rep.GpuError(f->getLocation(), "kernel '" + k.name + "' empties '" + f->getNameAsString() + "', which no kernel appends to: on the GPU only an appended vector's size is counted there",
                    "empty it in the control function (before the kernel), or append to it with push_back in the loop");
    printer.RestoreSizeReads(sizeReadsInLoop);
  }
  std::map<const FieldDecl*, SourceLocation> appends = ws.appends;
  for (auto* helper : printer.Uses().helpers) {
    WriteScanner hs(c);
    hs.helper = helper;
    hs.TraverseStmt(helper->getBody());
    markVectorWrites(hs);
    appends.insert(hs.appends.begin(), hs.appends.end());
  }
  for (auto& [field, loc] : appends)
    if (auto* m = FindMember(c.model, field->getNameAsString())) m->appendedByKernels = m->writtenByKernels = true;
  // On the CPU the threads run the original bodies of kernel_ functions (their loop is in the
  // control function) and of helpers: those that append get copies with a lock.
  std::vector<const FunctionDecl*> reached;
  if (k.rtv) reached.push_back(def);
  reached.insert(reached.end(), printer.Uses().helpers.begin(), printer.Uses().helpers.end());
  AddLockedCopies(c, reached);
  // Threads append in any order: a size read in the same kernel would see a partial count.
  CheckObjectSizeReads(c.rep, printer);
  for (auto& [field, loc] : printer.Uses().sizeReads)
    if (appends.count(field))
      c.rep.Error(loc, "kernel '" + k.name + "' reads the size of '" + field->getNameAsString() + "', which it appends to",
                  "the final size is known after the kernel: read it in a later kernel, or after the control function returns");
  k.structList = printer.Structs();
  k.constantList = printer.Constants();
  k.functionList = printer.Functions();
  k.atomics = printer.Uses().atomics;
  k.floatAtomics = printer.Uses().floatAtomics;
  if (!printer.Uses().virtualCalls.empty()) AnalyzeVirtualCalls(c, k, printer);
  k.composedCalls = printer.Uses().composedCalls;
  for (auto& [holder, method] : printer.Uses().composedCalls) {
    if (std::any_of(c.model.compositions.begin(), c.model.compositions.end(), [&](const Composition& x) { return x.holder == holder; }))
      continue;
    Composition comp;
    comp.holder = holder;
    for (auto* f : ClassFields(c.cls))
      if (auto* rd = f->getNameAsString() == holder ? PolymorphicPointee(f->getType()) : nullptr) comp.interfaceName = rd->getNameAsString();
    comp.implName = c.compositions.count(comp.interfaceName) ? c.compositions.at(comp.interfaceName) : "";
    c.model.compositions.push_back(comp);
  }
  for (auto* f : printer.Uses().memberVectors) {
    k.memberVectors.push_back(f->getNameAsString());
    if (auto* m = FindMember(c.model, f->getNameAsString())) m->usedByKernels = true;
    RequireReachable(c.rep, f, c.cls);
    QualType elem;
    const bool ispcDoubles = c.model.forIspc && IsStdVector(f->getType(), &elem) && elem.getCanonicalType()->isSpecificBuiltinType(BuiltinType::Double);
    if (IsStdVector(f->getType(), &elem) && !ispcDoubles && !LayoutMatchesCpp(c.ctx, elem, false) && !LayoutMatchesCpp(c.ctx, elem, true))
      c.rep.GpuError(f->getLocation(), "the elements of '" + f->getNameAsString() + "' have a C++ layout that a GPU buffer cannot reproduce",
                     "use int instead of bool, and 32-bit scalars and LiteMath vectors in structs");
  }
  std::sort(k.memberVectors.begin(), k.memberVectors.end());
  k.ownFunctionList = k.functionList;
  k.ownMemberVectors = k.memberVectors;
  // Images and samplers, in declaration order so that bindings stay stable across regenerations.
  for (auto* f : ClassFields(c.cls)) {
    const bool loaded = printer.Uses().loadedImages.count(f), stored = printer.Uses().storedImages.count(f);
    const bool sampled = printer.Uses().sampledImages.count(f), sampler = printer.Uses().samplers.count(f);
    if (!(loaded || stored || sampled || sampler || printer.Uses().sizedImages.count(f))) continue;
    RequireReachable(c.rep, f, c.cls);
    auto* m = FindMember(c.model, f->getNameAsString());
    if (!m) continue;
    m->usedByKernels = true;
    m->writtenByKernels = m->writtenByKernels || stored;
    if (loaded || stored) k.images.push_back({m->name, ImageUse::Storage, loaded, stored});
    if (sampled) k.images.push_back({m->name, ImageUse::Texture, false, false});
    if (sampler) k.images.push_back({m->name, ImageUse::Sampler, false, false});
  }
  // Image parameters after the members, in parameter order.
  for (auto* p : def->parameters()) {
    if (!printer.imageParams.count(p)) continue;
    const bool loaded = printer.Uses().loadedImages.count(p), stored = printer.Uses().storedImages.count(p);
    if (loaded || stored) k.images.push_back({p->getNameAsString(), ImageUse::Storage, loaded, stored, true});
    if (printer.Uses().sampledImages.count(p)) k.images.push_back({p->getNameAsString(), ImageUse::Texture, false, false, true});
  }
  for (auto& [image, sampler] : printer.Uses().samplePairs)
    (isa<FieldDecl>(image) ? k.samplePairs : k.paramSamplePairs).push_back({image->getNameAsString(), sampler->getNameAsString()});
  for (auto* f : ClassFields(c.cls)) {
    if (!printer.Uses().textureArrays.count(f)) continue;
    RequireReachable(c.rep, f, c.cls);
    if (auto* m = FindMember(c.model, f->getNameAsString())) {
      m->usedByKernels = true;
      k.textureArrays.push_back(m->name);
    }
  }
  std::sort(k.samplePairs.begin(), k.samplePairs.end());
  for (auto* f : printer.Uses().plainMembers) {
    auto* m = FindMember(c.model, f->getNameAsString());
    if (m) m->usedByKernels = true;
    if (m && !m->inClassData && !m->specialized && f->getAccess() != AS_private)
      c.rep.GpuError(f->getLocation(), "member '" + f->getNameAsString() + "' of type '" + f->getType().getAsString(c.ctx.getPrintingPolicy()) + "' has a C++ layout that a GPU buffer cannot reproduce",
                  "use int instead of bool, float4x4 instead of float3x3, or reorder struct fields so 16-byte types come first");
    RequireReachable(c.rep, f, c.cls);
  }
  for (auto& r : k.reductions)
    if (auto* m = r.local ? nullptr : FindMember(c.model, r.member)) { m->usedByKernels = true; m->writtenByKernels = true; }

  // CPU backend: the loop nest as the user wrote it, reduction targets renamed.
  if (!k.rtv) {
    Rewriter rw(c.ctx.getSourceManager(), c.ctx.getLangOpts());
    // Reduction targets get their per-thread names, shadowing locals their suffixes; appends go through a lock.
    // (Reduced locals too: each chunk of the loop reduces into a part of its own, crt_<local>Local.)
    struct Renamer : RecursiveASTVisitor<Renamer> {
      Rewriter& rw; ASTContext& ctx; const std::map<const FieldDecl*, ReduceOp>& red; const std::set<const VarDecl*>& locals;
      std::map<const VarDecl*, std::string> shadowing;  // ShadowingLocalName's answers, asked once per local
      Renamer(Rewriter& r, ASTContext& cx, const std::map<const FieldDecl*, ReduceOp>& m, const std::set<const VarDecl*>& l) : rw(r), ctx(cx), red(m), locals(l) {}
      // A local that shadows another name takes the suffix the GPU code gives it (-Wshadow).
      void Rename(const VarDecl* vd, SourceLocation at) {
        auto it = shadowing.find(vd);
        if (it == shadowing.end()) it = shadowing.emplace(vd, ShadowingLocalName(ctx, vd)).first;
        if (!it->second.empty() && !at.isMacroID()) rw.ReplaceText(at, vd->getName().size(), it->second);
      }
      bool VisitDeclRefExpr(DeclRefExpr* dr) {
        auto* vd = dyn_cast<VarDecl>(dr->getDecl());
        if (vd && locals.count(vd)) rw.ReplaceText(dr->getLocation(), vd->getName().size(), generated::ReductionLocal(vd->getNameAsString()));
        else if (vd) Rename(vd, dr->getLocation());
        return true;
      }
      bool VisitVarDecl(VarDecl* vd) {
        Rename(vd, vd->getLocation());
        return true;
      }
      bool VisitMemberExpr(MemberExpr* me) {
        auto* f = dyn_cast<FieldDecl>(me->getMemberDecl());
        if (f && red.count(f) && me->isImplicitAccess()) rw.ReplaceText(me->getMemberLoc(), f->getName().size(), generated::ReductionLocal(f->getNameAsString()));
        else if (f && red.count(f)) rw.ReplaceText(me->getSourceRange(), generated::ReductionLocal(f->getNameAsString()));
        return true;
      }
    } renamer(rw, c.ctx, ws.reductions, reducedLocals);
    struct PrivateConstants : RecursiveASTVisitor<PrivateConstants> {
      Rewriter& rw; ASTContext& ctx;
      PrivateConstants(Rewriter& r, ASTContext& cx) : rw(r), ctx(cx) {}
      // A private static constant of the class (static constexpr float PI): the derived class cannot
      // name it, so the loop gets its value, exactly (a float in hexadecimal), with its name beside.
      bool VisitDeclRefExpr(DeclRefExpr* dr) {
        auto* vd = dyn_cast<VarDecl>(dr->getDecl());
        Expr::EvalResult r;
        if (!vd || !vd->isStaticDataMember() || vd->getAccess() != AS_private || dr->getBeginLoc().isMacroID() || !dr->EvaluateAsRValue(r, ctx)) return true;
        std::string value;
        if (r.Val.isInt()) value = (r.Val.getInt().isSigned() ? std::to_string(r.Val.getInt().getExtValue()) : std::to_string(r.Val.getInt().getZExtValue())) + (dr->getType()->isUnsignedIntegerType() ? "u" : "");
        else if (r.Val.isFloat()) {
          char buf[64];
          std::snprintf(buf, sizeof buf, "%a", r.Val.getFloat().convertToDouble());
          value = buf;
        } else
          return true;
        rw.ReplaceText(dr->getSourceRange(), "static_cast<" + dr->getType().getUnqualifiedType().getAsString(ctx.getPrintingPolicy()) + ">(" + value +
                                                 " /*" + vd->getQualifiedNameAsString() + "*/)");
        return true;
      }
    } constants(rw, c.ctx);
    const ForStmt* outer = KernelLoopNest(c.ctx, body);
    renamer.TraverseStmt(const_cast<ForStmt*>(outer));
    for (auto* list : {&before, &after})
      for (auto* st : *list) constants.TraverseStmt(const_cast<Stmt*>(st));
    constants.TraverseStmt(const_cast<ForStmt*>(outer));
    // A flag every thread may set: stored atomically, so that the threads do not race on it.
    for (auto* bo : ws.constantStoreExprs) {
      SourceLocation end = Lexer::findLocationAfterToken(bo->getEndLoc(), tok::semi, c.ctx.getSourceManager(), c.ctx.getLangOpts(), false);
      if (end.isInvalid()) continue;
      rw.InsertTextBefore(bo->getBeginLoc(), "{\n#pragma omp atomic write\n");
      rw.InsertTextAfter(end, "\n}");
    }
    LockAppends(rw, outer);
    // The outer loop runs a chunk [crt_first, crt_last) of its iterations (crossrt::ParallelFor;
    // the template puts the chunk's parts of the reductions around the nest). Chunks go to threads
    // as they come free: iterations may cost very different amounts (a ray that hits against one
    // that misses). With static halves PrimaryRays_CPU cast the bunny's rays at 0.57-0.63x of
    // Embree, with chunks of 1024 at 0.71-0.75x (bench_lbvh, 2 threads). 2D kernels hand out rows.
    LoopHeader outerHeader;
    if (outer && LoopShapeProblem(c.ctx, outer, outerHeader).empty())
      k.cpuLoopHead = ChunkLoop(rw, c.ctx, outer, outerHeader, "crt_loop.parallel", k.dims == 1 ? "1024" : "1").head;
    // A loop whose body is a bare statement ends before its ';': take the ';' too.
    SourceLocation end = Lexer::findLocationAfterToken(outer->getEndLoc(), tok::semi, c.ctx.getSourceManager(), c.ctx.getLangOpts(), false);
    k.cpuLoopNest = CanonicalCode(end.isValid() ? rw.getRewrittenText(CharSourceRange::getCharRange(outer->getBeginLoc(), end))
                                                : rw.getRewrittenText(outer->getSourceRange()));
    // The CPU class copies the loop nest and what it uses; so does the ISPC class, whose kernels run
    // the nest as the CPU class does when that has been faster than SIMD lanes (crossrt::LaneChoice).
    if (c.model.forCpu) CopySourceDeclarations(c, def->getBody(), "kernel '" + k.name + "'");
    // The statements around the nest, with the private constants' values too.
    auto rewritten = [&](const Stmt* st) {
      auto& sm = c.ctx.getSourceManager();
      SourceLocation stEnd = Lexer::findLocationAfterToken(st->getEndLoc(), tok::semi, sm, c.ctx.getLangOpts(), false);
      if (st->getBeginLoc().isMacroID() || st->getEndLoc().isMacroID()) return StatementText(c, st);
      if (stEnd.isInvalid()) return rw.getRewrittenText(st->getSourceRange());  // a declaration, a block: its ';' or '}' included
      return rw.getRewrittenText(CharSourceRange::getCharRange(st->getBeginLoc(), stEnd));
    };
    for (auto* s : before) k.cpuPreamble += rewritten(s) + "\n";
    for (auto* s : before)
      if (auto* ds = dyn_cast<DeclStmt>(s))
        for (auto* d : ds->decls())
          if (auto* vd = dyn_cast<VarDecl>(d)) k.preambleLocals.push_back(vd->getNameAsString());
    k.cpuPreamble = CanonicalCode(k.cpuPreamble);
    for (auto* s : after) k.cpuPostamble += rewritten(s) + "\n";
    k.cpuPostamble = CanonicalCode(k.cpuPostamble);
  }
  c.model.kernels.push_back(k);
}

}  // namespace crossrt::engine
