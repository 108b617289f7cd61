// Control functions: the non-kernel methods that call kernels. Their bodies are rewritten twice, into
// the Vulkan class's ...Cmd recording (kernel calls become dispatches) and into the CPU class's code.
// Takes a control function; adds a Control to the model.
#include "generate/GeneratedNames.h"
#include "control/ControlFunctions.h"

#include "analyse/AnalysisContext.h"
#include "analyse/AstQueries.h"
#include "control/ControlRewriter.h"
#include "analyse/CpuCopies.h"
#include "analyse/KernelParams.h"
#include "analyse/Naming.h"
#include "analyse/VirtualCalls.h"
#include "analyse/WriteVisitor.h"

#include <clang/Lex/Lexer.h>

#include <algorithm>
#include <cctype>
#include <set>

using namespace clang;

namespace crossrt::engine {

bool IsPerThreadFunction(const CXXMethodDecl* md, const CXXRecordDecl* cls) {
  const FunctionDecl* def = nullptr;
  if (!md || IsKernelName(md->getName()) || !md->hasBody(def) || !def || !IsClassOrBase(md->getParent(), cls)) return false;
  struct Finder : RecursiveASTVisitor<Finder> {
    const FunctionDecl* def; bool found = false;
    explicit Finder(const FunctionDecl* d) : def(d) {}
    bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
      auto* k = call->getMethodDecl();
      if (!k || !IsKernelName(k->getName()) || IpvDims(k->getName())) return true;
      for (unsigned i = 0; i < call->getNumArgs() && i < k->getNumParams(); ++i)
        if (IsThreadIdName(k->getParamDecl(i)->getName()))
          if (auto* dr = dyn_cast<DeclRefExpr>(call->getArg(i)->IgnoreCasts()->IgnoreParens()))
            found |= isa<ParmVarDecl>(dr->getDecl()) && cast<ParmVarDecl>(dr->getDecl())->getDeclContext() == def;
      return true;
    }
  } finder(def);
  finder.TraverseStmt(def->getBody());
  return finder.found;
}

const Stmt* SingleStatement(const Stmt* s) {
  while (auto* cs = dyn_cast_or_null<CompoundStmt>(s)) {
    if (cs->size() != 1) return s;
    s = cs->body_front();
  }
  return s;
}

namespace {

// The generated control function copies its Image2D parameters to the GPU before its body runs
// and back after: host code of the body that changes one (resize, texel writes) would be lost.
void CheckImageParamsUnchanged(Context& c, const FunctionDecl* def, const std::string& control) {
  struct Finder : RecursiveASTVisitor<Finder> {
    Context& c;
    const FunctionDecl* def;
    const std::string& control;
    Finder(Context& cc, const FunctionDecl* d, const std::string& n) : c(cc), def(d), control(n) {}
    void Check(const CXXMethodDecl* md, const Expr* object, SourceLocation loc) {
      auto* dr = object ? dyn_cast<DeclRefExpr>(object->IgnoreParenImpCasts()) : nullptr;
      auto* p = dr ? dyn_cast<ParmVarDecl>(dr->getDecl()) : nullptr;
      if (!p || p->getDeclContext() != def || !md || md->isConst() || !IsImage2D(p->getType().getNonReferenceType().getUnqualifiedType())) return;
      c.rep.RecordingError(loc, "control function '" + control + "' changes Image2D parameter '" + p->getNameAsString() + "' on the host ('" + md->getNameAsString() + "')",
                        "its GPU copy is made before the body runs: size and fill the image before calling '" + control + "', and write its texels in a kernel");
    }
    bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
      Check(call->getMethodDecl(), call->getImplicitObjectArgument(), call->getBeginLoc());
      return true;
    }
    bool VisitCXXOperatorCallExpr(CXXOperatorCallExpr* op) {
      if (op->getNumArgs() > 0) Check(dyn_cast_or_null<CXXMethodDecl>(op->getDirectCallee()), op->getArg(0), op->getBeginLoc());
      return true;
    }
  } finder(c, def, control);
  finder.TraverseStmt(def->getBody());
}

// `text` with each whole identifier `from` replaced by `to`, for each (from, to) pair.
std::string RenameIdentifiers(const std::string& text, const std::vector<std::pair<std::string, std::string>>& names) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    if (!(std::isalpha(static_cast<unsigned char>(text[i])) || text[i] == '_')) {
      out += text[i++];
      continue;
    }
    size_t end = i;
    while (end < text.size() && (std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_')) ++end;
    std::string word = text.substr(i, end - i);
    for (auto& [from, to] : names)
      if (word == from) {
        word = to;
        break;
      }
    out += word;
    i = end;
  }
  return out;
}

}  // namespace

// Whether a kernel may be called after statement s runs: one written after it, or one in a loop
// around it (the next round calls it after s).
static bool KernelMayFollow(ASTContext& ctx, const FunctionDecl* def, const Stmt* s) {
  struct Finder : RecursiveASTVisitor<Finder> {
    std::vector<const CXXMemberCallExpr*> kernels;
    std::vector<const Stmt*> loops;
    bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
      if (auto* md = call->getMethodDecl(); md && IsKernelName(md->getName())) kernels.push_back(call);
      return true;
    }
    bool VisitStmt(Stmt* st) {
      if (isa<ForStmt, WhileStmt, DoStmt, CXXForRangeStmt>(st)) loops.push_back(st);
      return true;
    }
  } finder;
  finder.TraverseStmt(def->getBody());
  const SourceManager& sm = ctx.getSourceManager();
  auto before = [&](SourceLocation a, SourceLocation b) { return sm.isBeforeInTranslationUnit(a, b); };
  auto within = [&](SourceLocation at, const Stmt* outer) { return !before(at, outer->getBeginLoc()) && !before(outer->getEndLoc(), at); };
  for (auto* call : finder.kernels)
    if (before(s->getEndLoc(), call->getBeginLoc())) return true;
  for (auto* loop : finder.loops)
    if (within(s->getBeginLoc(), loop))
      for (auto* call : finder.kernels)
        if (within(call->getBeginLoc(), loop)) return true;
  return false;
}

// Changes of CRT_SPECIALIZE members in a control function: assignments anywhere in its body (a loop's
// header, a case, a comma expression), in the member functions it calls (at the call), and through
// non-const reference arguments (std::swap). Where a kernel call can follow, the Vulkan class would
// run that kernel with pipelines made for the value before the change: an error there.
static void CheckSpecializedChanges(Context& c, const std::string& control, const FunctionDecl* def) {
  struct Changes : WriteVisitor<Changes> {
    const CXXRecordDecl* cls = nullptr;
    const Stmt* anchor = nullptr;  // while in a called member function's body: the call in the control function
    std::set<const FunctionDecl*> seen;
    std::vector<std::pair<const FieldDecl*, const Stmt*>> found;
    void Written(const Expr* target, SourceLocation) {
      if (auto* f = RootField(target); f && IsSpecializedMember(f)) found.push_back({f, anchor ? anchor : target});
    }
    bool VisitCallExpr(CallExpr* call) {
      const FunctionDecl* fd = call->getDirectCallee();
      if (!fd) return true;
      ReferenceArguments(call);
      auto* md = dyn_cast<CXXMethodDecl>(fd);
      const FunctionDecl* body = nullptr;
      if (md && !IsKernelName(md->getName()) && IsClassOrBase(md->getParent(), cls) && md->hasBody(body) && body && seen.insert(body).second) {
        const Stmt* saved = anchor;
        if (!anchor) anchor = call;
        TraverseStmt(body->getBody());
        anchor = saved;
      }
      return true;
    }
  } changes;
  changes.cls = c.cls;
  changes.TraverseStmt(def->getBody());
  std::set<std::pair<const FieldDecl*, const Stmt*>> reported;
  for (auto& [f, at] : changes.found)
    if (reported.insert({f, at}).second && KernelMayFollow(c.ctx, def, at))
      c.rep.RecordingError(at->getBeginLoc(), "control function '" + control + "' changes member '" + f->getNameAsString() +
                           "', which is CRT_SPECIALIZE, where a kernel call can follow: the pipelines are made for its value before the commands are recorded",
                           "set it before calling '" + control + "' (the call then makes the pipelines again), or after its last kernel call");
}

namespace {

// The bound of the Block's loop over `var` (for (int tid = 0; tid < a_size; tid++): "a_size"), or "".
std::string LoopBound(const FunctionDecl* def, const VarDecl* var) {
  struct Finder : RecursiveASTVisitor<Finder> {
    const VarDecl* var; const Expr* bound = nullptr;
    bool VisitForStmt(ForStmt* fs) {
      auto* cond = dyn_cast_or_null<BinaryOperator>(fs->getCond());
      auto* dr = cond && (cond->getOpcode() == BO_LT) ? dyn_cast<DeclRefExpr>(cond->getLHS()->IgnoreParenImpCasts()) : nullptr;
      if (dr && dr->getDecl() == var) bound = cond->getRHS();
      return !bound;
    }
  } finder;
  finder.var = var;
  finder.TraverseStmt(def->getBody());
  if (!finder.bound) return "";
  const ASTContext& ctx = def->getASTContext();
  return Lexer::getSourceText(CharSourceRange::getTokenRange(finder.bound->getSourceRange()), ctx.getSourceManager(), ctx.getLangOpts()).str();
}

// kernel_slicer's ...Block form: `MainFuncBlock(tidX, tidY, out_color, passes)` runs the per-thread
// `MainFunc(tidX, tidY, out_color)` over every thread, and the pointer sizes are written on MainFunc.
// The size annotation of the sibling's parameter of the same name, in the Block's terms: a name of
// the Block's parameters or the class's members as it is; the sibling's thread id (size("tid")) as
// the bound of the Block's loop whose variable the Block passes for it. "" where a name is neither.
std::string SiblingSize(const CXXRecordDecl* cls, const CXXMethodDecl* block, const std::string& param) {
  const std::string name = block->getNameAsString();
  if (name.size() <= 5 || name.compare(name.size() - 5, 5, "Block") != 0) return "";
  const std::string sibling = name.substr(0, name.size() - 5);
  const FunctionDecl* blockDef = nullptr;
  block->hasBody(blockDef);
  // The sibling's parameters as the Block's call passes them: index -> the Block's loop variable.
  auto passedLoopVar = [&](const CXXMethodDecl* m, unsigned index) -> const VarDecl* {
    struct Calls : RecursiveASTVisitor<Calls> {
      const CXXMethodDecl* m; unsigned index; const VarDecl* var = nullptr;
      bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
        if (call->getMethodDecl() && call->getMethodDecl()->getCanonicalDecl() == m->getCanonicalDecl() && index < call->getNumArgs())
          if (auto* dr = dyn_cast<DeclRefExpr>(call->getArg(index)->IgnoreParenImpCasts())) var = dyn_cast<VarDecl>(dr->getDecl());
        return !var;
      }
    } calls;
    calls.m = m;
    calls.index = index;
    if (blockDef) calls.TraverseStmt(blockDef->getBody());
    return calls.var;
  };
  for (const CXXMethodDecl* m : cls->methods()) {
    if (m->getNameAsString() != sibling) continue;
    for (const FunctionDecl* redecl : m->redecls())
      for (const ParmVarDecl* p : redecl->parameters()) {
        if (p->getNameAsString() != param) continue;
        for (auto* a : p->specific_attrs<AnnotateAttr>()) {
          if (!a->getAnnotation().starts_with("crossrt.size=")) continue;
          const std::string expr = a->getAnnotation().substr(13).str();
          std::string out;
          bool known = true;
          for (size_t i = 0; i < expr.size() && known;) {
            if (!(std::isalpha(static_cast<unsigned char>(expr[i])) || expr[i] == '_')) { out += expr[i++]; continue; }
            size_t end = i;
            while (end < expr.size() && (std::isalnum(static_cast<unsigned char>(expr[end])) || expr[end] == '_')) ++end;
            const std::string id = expr.substr(i, end - i);
            i = end;
            if (std::any_of(block->param_begin(), block->param_end(), [&](const ParmVarDecl* b) { return b->getNameAsString() == id; }) ||
                std::any_of(cls->field_begin(), cls->field_end(), [&](const FieldDecl* f) { return f->getNameAsString() == id; })) {
              out += id;
              continue;
            }
            // The sibling's thread id: the count of the Block's loop that passes it.
            std::string bound;
            for (unsigned k = 0; k < redecl->getNumParams() && bound.empty(); ++k)
              if (redecl->getParamDecl(k)->getNameAsString() == id && IsThreadIdName(id))
                if (const VarDecl* var = passedLoopVar(m, k); var && blockDef) bound = LoopBound(blockDef, var);
            known = !bound.empty();
            out += "(" + bound + ")";
          }
          if (known) return out;
        }
      }
  }
  return "";
}

// A pointer the size annotation forgot, as kernel_slicer infers it: where the control function only
// passes `p` to kernel1D_ kernels, straight, for a parameter each reads and writes only as
// `q[i]`, with i its loop's variable counting from 0 to a bound it was given (`i < n`, `i <= n`),
// the size is that bound in the control function's terms ("a_size", "a_size + 1"). "" otherwise.
std::string LoopSize(const FunctionDecl* def, const ParmVarDecl* p, const CXXRecordDecl* cls) {
  struct Calls : RecursiveASTVisitor<Calls> {
    const ParmVarDecl* p; const CXXRecordDecl* cls; std::set<std::string> sizes; bool other = false; int passed = 0;  // uses not yet known to be kernels' arguments
    bool VisitDeclRefExpr(DeclRefExpr* dr) {
      if (dr->getDecl() == p) ++passed;  // every use of p must be an argument of a kernel below
      return true;
    }
    bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
      auto* kernel = call->getMethodDecl();
      const FunctionDecl* kdef = nullptr;
      for (unsigned i = 0; i < call->getNumArgs(); ++i) {
        auto* arg = dyn_cast<DeclRefExpr>(call->getArg(i)->IgnoreParenImpCasts());
        if (!arg || arg->getDecl() != p) continue;
        if (!kernel || !kernel->getName().starts_with("kernel1D_") || !kernel->hasBody(kdef) || !kdef || i >= kdef->getNumParams()) {
          other = true;
          continue;
        }
        std::string size = KernelLoopSize(call, kdef, kdef->getParamDecl(i));
        if (size.empty()) other = true;
        else sizes.insert(size), --passed;
      }
      return true;
    }
    // The size the kernel's loop gives its parameter q, in terms of the call's arguments, or "".
    std::string KernelLoopSize(const CXXMemberCallExpr* call, const FunctionDecl* kdef, const ParmVarDecl* q) {
      const ForStmt* loop = nullptr;
      if (auto* body = dyn_cast<CompoundStmt>(kdef->getBody()))
        for (auto* st : body->body())
          if ((loop = dyn_cast<ForStmt>(st))) break;
      auto* init = loop ? dyn_cast_or_null<DeclStmt>(loop->getInit()) : nullptr;
      auto* var = init && init->isSingleDecl() ? dyn_cast<VarDecl>(init->getSingleDecl()) : nullptr;
      auto* cond = loop ? dyn_cast_or_null<BinaryOperator>(loop->getCond()) : nullptr;
      Expr::EvalResult start;
      if (!var || !var->getInit() || !var->getInit()->EvaluateAsInt(start, kdef->getASTContext()) || start.Val.getInt() != 0 || !cond ||
          (cond->getOpcode() != BO_LT && cond->getOpcode() != BO_LE))
        return "";
      auto* lhs = dyn_cast<DeclRefExpr>(cond->getLHS()->IgnoreParenImpCasts());
      auto* bound = dyn_cast<DeclRefExpr>(cond->getRHS()->IgnoreParenImpCasts());
      auto* boundParam = bound ? dyn_cast<ParmVarDecl>(bound->getDecl()) : nullptr;
      if (!lhs || lhs->getDecl() != var || !boundParam || boundParam->getFunctionScopeIndex() >= call->getNumArgs()) return "";
      auto* boundArg = dyn_cast<DeclRefExpr>(call->getArg(boundParam->getFunctionScopeIndex())->IgnoreParenImpCasts());
      if (!boundArg || !isa<ParmVarDecl>(boundArg->getDecl())) return "";
      // Every use of q in the kernel: q[var].
      struct Uses : RecursiveASTVisitor<Uses> {
        const ParmVarDecl* q; const VarDecl* var; unsigned all = 0, indexed = 0;
        bool VisitDeclRefExpr(DeclRefExpr* dr) { all += dr->getDecl() == q; return true; }
        bool VisitArraySubscriptExpr(ArraySubscriptExpr* as) {
          auto* base = dyn_cast<DeclRefExpr>(as->getBase()->IgnoreParenImpCasts());
          auto* index = dyn_cast<DeclRefExpr>(as->getIdx()->IgnoreParenImpCasts());
          indexed += base && base->getDecl() == q && index && index->getDecl() == var;
          return true;
        }
      } uses;
      uses.q = q;
      uses.var = var;
      uses.TraverseStmt(kdef->getBody());
      if (uses.all == 0 || uses.all != uses.indexed) return "";
      const std::string n = boundArg->getDecl()->getNameAsString();
      return cond->getOpcode() == BO_LE ? n + " + 1" : n;
    }
  } calls;
  calls.p = p;
  calls.cls = cls;
  calls.TraverseStmt(def->getBody());
  return !calls.other && calls.passed == 0 && calls.sizes.size() == 1 ? *calls.sizes.begin() : "";
}

// Whether the control function hands pointer parameter `p` on: to a member function of the class
// (a kernel, or one that may call kernels), or into a variable. Otherwise only host code uses it
// (memcpy(out, m_v.data(), ...) after the kernels), as the original does, and no kernel needs a copy.
bool HandedOn(const FunctionDecl* def, const ParmVarDecl* p, const CXXRecordDecl* cls) {
  struct Finder : RecursiveASTVisitor<Finder> {
    const ParmVarDecl* p; const CXXRecordDecl* cls; bool found = false;
    bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
      auto* md = call->getMethodDecl();
      if (md && IsClassOrBase(md->getParent(), cls))
        for (auto* arg : call->arguments()) found |= Mentions(arg, p);
      return true;
    }
    bool VisitVarDecl(VarDecl* vd) { found |= vd->getInit() && vd->getType()->isPointerType() && Mentions(vd->getInit(), p); return true; }
    bool VisitBinaryOperator(BinaryOperator* bo) { found |= bo->isAssignmentOp() && bo->getType()->isPointerType() && Mentions(bo->getRHS(), p); return true; }
  } finder;
  finder.p = p;
  finder.cls = cls;
  finder.TraverseStmt(def->getBody());
  return finder.found;
}

}  // namespace

bool IsHostOnlyPointer(const ParmVarDecl* p, const CXXRecordDecl* cls) {
  auto* md = dyn_cast<CXXMethodDecl>(p->getDeclContext());
  const FunctionDecl* def = nullptr;
  if (!md || !p->getType()->isPointerType() || !md->hasBody(def) || !def || IsKernelName(md->getName())) return false;
  unsigned index = p->getFunctionScopeIndex();
  for (const FunctionDecl* redecl : md->redecls())
    if (index < redecl->getNumParams())
      for (auto* a : redecl->getParamDecl(index)->specific_attrs<AnnotateAttr>())
        if (a->getAnnotation().starts_with("crossrt.size=")) return false;
  if (!SiblingSize(cls, md, md->getParamDecl(index)->getNameAsString()).empty()) return false;
  return !HandedOn(def, def->getParamDecl(index), cls);
}

void AnalyzeControl(Context& c, const CXXMethodDecl* md, const FunctionDecl* def) {
  Control ctrl;
  ctrl.name = md->getNameAsString();
  ctrl.sourceFile = BaseName(FileOf(c.ctx, def->getLocation()));
  ctrl.definedAt = PlaceOf(c.ctx, def->getLocation());
  ctrl.isConst = md->isConst();
  ctrl.isVirtual = md->isVirtual();
  if (!ctrl.isVirtual)
    c.rep.Warning(md->getLocation(), "control function '" + ctrl.name + "' is not virtual: called through a pointer to " + c.cls->getNameAsString() +
                  " (as the factories return it) it runs " + c.cls->getNameAsString() + "::" + ctrl.name + " as written, on one CPU core",
                  "declare it 'virtual' in " + c.cls->getNameAsString() + " so that the generated classes override it; until then only a pointer to the "
                  "generated class (or its " + ctrl.name + "Cmd) runs it translated");
  CheckSpecializedChanges(c, ctrl.name, def);
  if (!md->getReturnType()->isVoidType()) {
    c.rep.Error(md->getLocation(), "control function '" + ctrl.name + "' returns a value",
                "return results through size-annotated pointer parameters or members; control functions return void");
    return;
  }
  // The definition's parameter names, which its body uses; a size annotation may be on any
  // declaration, in terms of that declaration's names.
  std::vector<std::pair<std::string, std::string>> declaredNames;  // (a declaration's name, the definition's)
  for (auto* redecl : md->redecls())
    for (unsigned i = 0; i < redecl->getNumParams() && i < def->getNumParams(); ++i)
      if (redecl->getParamDecl(i)->getName() != def->getParamDecl(i)->getName() && !redecl->getParamDecl(i)->getName().empty())
        declaredNames.push_back({redecl->getParamDecl(i)->getNameAsString(), def->getParamDecl(i)->getNameAsString()});
  for (unsigned i = 0; i < md->getNumParams(); ++i) {
    auto* p = md->getParamDecl(i);
    ControlParam cp;
    cp.name = def->getParamDecl(i)->getNameAsString();
    if (cp.name.empty()) cp.name = "a_unnamed" + std::to_string(i);  // as ParamDecl() spells it
    cp.declText = ParamDecl(c.ctx, p, def->getParamDecl(i), i);
    ctrl.paramsDecl += (i ? ", " : "") + cp.declText;
    ctrl.argsForward += (i ? ", " : "") + cp.name;
    if (p->getType()->isPointerType()) {
      cp.isPointer = true;
      QualType pointee = p->getType()->getPointeeType();
      cp.isConst = pointee.isConstQualified();
      cp.pointeeCpp = CppTypeName(c.ctx, pointee);
      for (auto* redecl : md->redecls())
        for (auto* a : redecl->getParamDecl(i)->specific_attrs<AnnotateAttr>())
          if (a->getAnnotation().starts_with("crossrt.size=") && cp.sizeExpr.empty())
            cp.sizeExpr = RenameIdentifiers(a->getAnnotation().substr(13).str(), declaredNames);
      if (cp.sizeExpr.empty())  // kernel_slicer's XBlock: the size is on X's parameter of the same name
        cp.sizeExpr = RenameIdentifiers(SiblingSize(c.cls, md, p->getNameAsString()), declaredNames);
      cp.hostOnly = cp.sizeExpr.empty() && IsHostOnlyPointer(def->getParamDecl(i), c.cls);
      if (cp.sizeExpr.empty() && !cp.hostOnly && !c.model.forCpu) {  // kernel_slicer's way: from the loop that indexes it
        cp.sizeExpr = LoopSize(def, def->getParamDecl(i), c.cls);
        if (!cp.sizeExpr.empty())
          c.rep.Note(p->getLocation(), "pointer parameter '" + cp.name + "' of control function '" + ctrl.name + "' has no size: " + cp.sizeExpr +
                                           " elements, as the loop of the kernel it is handed to indexes them");
      }
      if (cp.sizeExpr.empty() && !cp.hostOnly && !c.model.forCpu)  // (an ISPC class reads the C++ memory in place: no copies to size)
        c.rep.GpuError(p->getLocation(), "pointer parameter '" + cp.name + "' of control function '" + ctrl.name + "' has no size",
                    "annotate it with its element count, e.g. '[[crossrt::size(\"n\")]] const float* " + cp.name +
                    "' or 'const float* " + cp.name + " __attribute__((size(\"n\")))'");
    }
    QualType texel;
    if (IsImage2D(p->getType().getNonReferenceType().getUnqualifiedType(), &texel)) {
      cp.isImage = true;
      cp.isConst = !p->getType()->isReferenceType() || p->getType().getNonReferenceType().isConstQualified();
      cp.pointeeCpp = CppTypeName(c.ctx, texel);
      if (auto format = ImageFormatOf(texel)) cp.vkFormat = format->vkFormat;
      else c.rep.GpuError(p->getLocation(), "parameter '" + cp.name + "' of control function '" + ctrl.name + "' is an Image2D of '" +
                       texel.getAsString(c.ctx.getPrintingPolicy()) + "', which GPU images cannot hold", "use Image2D<float4>, Image2D<float> or Image2D<uint32_t>");
    }
    ctrl.params.push_back(cp);
  }
  CheckImageParamsUnchanged(c, def, ctrl.name);
  CopySourceDeclarations(c, def->getBody(), "control function '" + ctrl.name + "'");
  ControlRewriter rw(c, md, def, ctrl);
  rw.Run();
  c.model.controls.push_back(ctrl);
}

void ControlRewriter::Run() {
  CheckAppendedUses();
  RemoveOpenMpPragmas();
  FindHostTail();
  Visit(m_def->getBody());
  CheckTemporaryUses();
  CheckHostVectorUses();
  SynchronizeHostVectors();
  SplitAtHostReads();
  MoveHostTail();
  m_ctrl.vulkanCmdBody = CanonicalCode(m_gpu.getRewrittenText(m_def->getBody()->getSourceRange()));
  m_ctrl.cpuBody = CanonicalCode(m_cpu.getRewrittenText(m_def->getBody()->getSourceRange()));
}

void ControlRewriter::RemoveOpenMpPragmas() {
  auto& sm = m_c.ctx.getSourceManager();
  const SourceRange body = m_def->getBody()->getSourceRange();
  const SourceLocation begin = sm.getExpansionLoc(body.getBegin()), end = sm.getExpansionLoc(body.getEnd());
  if (sm.getFileID(begin) != sm.getFileID(end)) return;
  const unsigned from = sm.getFileOffset(begin), to = sm.getFileOffset(end);
  const StringRef text = sm.getBufferData(sm.getFileID(begin));
  for (unsigned at = from; at < to;) {
    const size_t eol = text.find('\n', at);
    const unsigned lineEnd = eol == StringRef::npos ? unsigned(text.size()) : unsigned(eol);
    const StringRef line = text.substr(at, lineEnd - at).ltrim();
    if (line.starts_with("#") && line.drop_front().ltrim().starts_with("pragma") &&
        line.drop_front().ltrim().drop_front(6).ltrim().starts_with("omp")) {
      const SourceLocation start = begin.getLocWithOffset(int(at - from));
      m_gpu.RemoveText(start, lineEnd - at);
      m_cpu.RemoveText(start, lineEnd - at);
    }
    at = lineEnd + 1;
  }
}

std::string ControlRewriter::BufferArg(const Expr* arg) {
  const Expr* e = arg->IgnoreParenImpCasts();
  if (auto* dr = dyn_cast<DeclRefExpr>(e))
    if (auto* p = dyn_cast<ParmVarDecl>(dr->getDecl()); p && p->getDeclContext() == m_def)
      return generated::kInOutPrefix + m_ctrl.name + "." + p->getNameAsString();
  const Expr* offset = nullptr;
  if (auto* bo = dyn_cast<BinaryOperator>(e); bo && bo->getOpcode() == BO_Add) {
    offset = bo->getRHS();
    e = bo->getLHS()->IgnoreParenImpCasts();
  }
  if (auto* mc = dyn_cast<CXXMemberCallExpr>(e); mc && mc->getMethodDecl()->getName() == "data") {
    if (auto* f = ThisField(mc->getImplicitObjectArgument()); f && IsStdVector(f->getType())) {
      if (auto* m = FindMember(m_c.model, f->getNameAsString())) m->usedByKernels = true;
      std::string view = generated::kVectorCopies + "." + f->getNameAsString() + ".View(";
      if (offset) {
        auto* m = FindMember(m_c.model, f->getNameAsString());
        view += "sizeof(" + (m ? m->elemCppType : std::string("float")) + ") * size_t(" + m_c.Text(offset->getSourceRange()) + ")";
      }
      return view + ")";
    }
  }
  if (auto* mc = dyn_cast<CXXMemberCallExpr>(e); mc && mc->getMethodDecl()->getName() == "data")
    if (auto* dr = dyn_cast<DeclRefExpr>(mc->getImplicitObjectArgument()->IgnoreParenImpCasts()))
      if (auto* vd = dyn_cast<VarDecl>(dr->getDecl()); vd && vd->hasLocalStorage() && IsStdVector(vd->getType())) {
        auto* t = Temporary(vd);
        if (!t) return "{}";
        m_temporaryUses.insert(dr);
        std::string view = generated::kTemporaries + "." + t->buffer + ".View(";
        if (offset) view += "sizeof(" + t->cppType + ") * size_t(" + m_c.Text(offset->getSourceRange()) + ")";
        return view + ")";
      }
  m_c.rep.RecordingError(arg->getBeginLoc(), "pointer argument of a kernel call must be a parameter of '" + m_ctrl.name + "', 'member.data()' or a local std::vector's data() (+ offset)",
                      "pass the control function's size-annotated pointer, a std::vector member's data(), or a std::vector declared in '" + m_ctrl.name + "'");
  return "{}";
}

void ControlRewriter::WrittenThrough(const Expr* arg) {
  const Expr* e = arg->IgnoreParenImpCasts();
  if (auto* bo = dyn_cast<BinaryOperator>(e); bo && bo->getOpcode() == BO_Add) e = bo->getLHS()->IgnoreParenImpCasts();
  auto* mc = dyn_cast<CXXMemberCallExpr>(e);
  if (!mc || !mc->getMethodDecl() || mc->getMethodDecl()->getName() != "data") return;
  const FieldDecl* f = ThisField(mc->getImplicitObjectArgument());
  const Member* m = f ? FindMember(m_c.model, f->getNameAsString()) : nullptr;
  if (m && m->kind == MemberKind::Vector && std::find(m_ctrl.vectorsWritten.begin(), m_ctrl.vectorsWritten.end(), m->name) == m_ctrl.vectorsWritten.end())
    m_ctrl.vectorsWritten.push_back(m->name);
}

const Control::LocalBuffer* ControlRewriter::Temporary(const VarDecl* vd) {
  if (auto it = m_temporaries.find(vd); it != m_temporaries.end()) return &it->second;
  QualType element;
  IsStdVector(vd->getType(), &element);
  const std::string local = vd->getNameAsString();
  // Declared at the top of the control function's body, so that the buffer is sized once per call.
  const DeclStmt* decl = nullptr;
  if (auto* body = dyn_cast<CompoundStmt>(m_def->getBody()))
    for (auto* st : body->body())
      if (auto* ds = dyn_cast<DeclStmt>(st); ds && ds->isSingleDecl() && ds->getSingleDecl() == vd) decl = ds;
  auto* ctor = dyn_cast_or_null<CXXConstructExpr>(vd->getInit() ? vd->getInit()->IgnoreImplicit() : nullptr);
  const unsigned args = ctor ? unsigned(std::count_if(ctor->arg_begin(), ctor->arg_end(), [](const Expr* a) { return !isa<CXXDefaultArgExpr>(a); })) : 0;
  const bool countCtor = ctor && (args == 1 || args == 2) && ctor->getArg(0)->getType()->isIntegerType();
  if (!decl || !countCtor) {
    m_c.rep.RecordingError(vd->getLocation(), "std::vector '" + local + "' is passed to a kernel, but the GPU's copy of a local vector is made only from 'std::vector<T> " + local +
                           "(n)' or '(n, value)' declared on its own at the top of '" + m_ctrl.name + "'",
                           "declare it as 'std::vector<T> " + local + "(n);' at the top of the function, or make it a member");
    return nullptr;
  }
  const ASTContext& ctx = m_c.ctx;
  if (args == 2 && ctx.getTypeSize(element) != 32) {
    m_c.rep.RecordingError(ctor->getArg(1)->getBeginLoc(), "the GPU fills a local vector with a value of 32 bits, not of " + std::to_string(ctx.getTypeSize(element)) + " bits",
                           "declare it as 'std::vector<T> " + local + "(n);' and fill it in a kernel");
    return nullptr;
  }
  Control::LocalBuffer t;
  t.buffer = m_ctrl.name + "_" + local;
  t.cppType = CppTypeName(ctx, element);
  t.local = local;
  const std::string bytes = "sizeof(" + t.cppType + ") * " + local + ".size()";
  const std::string bits = args == 2 ? "crossrt::Bits32(" + t.cppType + "(" + m_c.Text(ctor->getArg(1)->getSourceRange()) + "))" : "0u";
  SourceLocation end = Lexer::findLocationAfterToken(decl->getEndLoc(), tok::semi, ctx.getSourceManager(), ctx.getLangOpts(), false);
  if (end.isInvalid()) end = decl->getEndLoc().getLocWithOffset(1);
  m_gpu.InsertTextAfter(end, "\n  // " + local + " on the GPU: a buffer of the class, filled as the constructor fills the vector\n"
                        "  crossrt::EnsureSize(crt_ctx, crt_temporaries." + t.buffer + ", " + bytes + ");\n"
                        "  crossrt::FillCmd(crt_cmd, crt_temporaries." + t.buffer + ".View(), (" + bytes + " + 3) / 4 * 4, " + bits + ");");
  m_ctrl.temporaries.push_back(t);
  return &m_temporaries.emplace(vd, t).first->second;
}

void ControlRewriter::CheckTemporaryUses() {
  struct Uses : RecursiveASTVisitor<Uses> {
    ControlRewriter& rw;
    explicit Uses(ControlRewriter& r) : rw(r) {}
    bool VisitCXXMemberCallExpr(CXXMemberCallExpr* mc) {
      auto* dr = dyn_cast<DeclRefExpr>(mc->getImplicitObjectArgument()->IgnoreParenImpCasts());
      const std::string n = mc->getMethodDecl() ? mc->getMethodDecl()->getNameAsString() : "";
      if (dr && (n == "size" || n == "empty")) rw.m_temporaryUses.insert(dr);
      return true;
    }
    bool VisitDeclRefExpr(DeclRefExpr* dr) {
      auto* vd = dyn_cast<VarDecl>(dr->getDecl());
      auto it = vd ? rw.m_temporaries.find(vd) : rw.m_temporaries.end();
      if (it == rw.m_temporaries.end() || rw.m_temporaryUses.count(dr)) return true;
      rw.m_c.rep.RecordingError(dr->getLocation(), "'" + it->second.local + "' is used on the host, but the kernels of '" + rw.m_ctrl.name +
                                "' read and write its GPU copy", "pass " + it->second.local + ".data() only to kernels; to read the results make it a member "
                                "(or a size-annotated parameter), which the generated class copies back");
      return true;
    }
  } uses(*this);
  if (!m_temporaries.empty()) uses.TraverseStmt(const_cast<Stmt*>(m_def->getBody()));
}

std::string ControlRewriter::ImageArg(const ParmVarDecl* p, const Expr* arg) {
  const Expr* e = arg->IgnoreParenImpCasts();
  if (auto* dr = dyn_cast<DeclRefExpr>(e))
    if (auto* cp = dyn_cast<ParmVarDecl>(dr->getDecl()); cp && cp->getDeclContext() == m_def)
      return generated::kInOutPrefix + m_ctrl.name + "." + cp->getNameAsString();
  if (auto* f = ThisField(e); f && IsImage2D(f->getType())) {
    const std::string name = f->getNameAsString();
    RequireReachable(m_c.rep, f, m_c.cls);
    if (auto* m = FindMember(m_c.model, name)) {
      m->usedByKernels = true;
      const bool written = !p->getType().getNonReferenceType().isConstQualified();
      m->writtenByKernels = m->writtenByKernels || written;
      auto& list = m_ctrl.imagesWritten;
      if (written && std::find(list.begin(), list.end(), name) == list.end()) list.push_back(name);
    }
    return "crossrt::ImageView(crt_images." + name + ", crt_images." + name + "Width, crt_images." + name + "Height)";
  }
  m_c.rep.RecordingError(arg->getBeginLoc(), "Image2D argument of a kernel call must be an Image2D parameter of '" + m_ctrl.name + "' or an Image2D member",
                      "an image local to '" + m_ctrl.name + "' has no GPU copy: make it a member (its GPU copy is kept between calls) or a parameter of '" +
                          m_ctrl.name + "'");
  return "{}";
}

std::string ControlRewriter::Args(const CXXMemberCallExpr* call, bool skipThreadIds) {
  std::string out;
  auto* md = call->getMethodDecl();
  for (unsigned i = 0; i < call->getNumArgs() && i < md->getNumParams(); ++i) {
    auto* p = md->getParamDecl(i);
    if (skipThreadIds && IsThreadIdName(p->getName())) continue;
    const Expr* arg = call->getArg(i);
    if (isa<CXXDefaultArgExpr>(arg)) continue;
    if (p->getType()->isPointerType()) CheckNotThreadState(md, p, arg);
    if (IsImageParam(p)) out += ", " + ImageArg(p, arg);
    else out += ", " + (p->getType()->isPointerType() ? BufferArg(arg) : m_c.Text(arg->getSourceRange()));
    if (p->getType()->isPointerType() && !p->getType()->getPointeeType().isConstQualified()) WrittenThrough(arg);
  }
  return out;
}

void ControlRewriter::CheckNotThreadState(const CXXMethodDecl* md, const ParmVarDecl* p, const Expr* arg) {
  if (!m_c.threadState.count({md->getNameAsString(), p->getNameAsString()})) return;
  m_c.rep.GpuError(arg->getBeginLoc(), "parameter '" + p->getNameAsString() + "' of '" + md->getNameAsString() +
                "' gets a local's address in a thread loop, so on the GPU it holds one value per thread, but here it is given a buffer",
                "pass the address of a local declared in the thread loop everywhere, or give the kernel a separate buffer parameter");
}

void ControlRewriter::Note(const CXXMemberCallExpr* call) {
  std::string n = call->getMethodDecl()->getNameAsString();
  if (std::find(m_ctrl.kernelsCalled.begin(), m_ctrl.kernelsCalled.end(), n) == m_ctrl.kernelsCalled.end())
    m_ctrl.kernelsCalled.push_back(n);
}

void ControlRewriter::RecordMemberWrite(const Stmt* s) {
  if (std::find(m_tail.begin(), m_tail.end(), s) != m_tail.end()) return;  // runs on the host after the kernels
  RecordClear(s);
  if (auto* ewc = dyn_cast_or_null<ExprWithCleanups>(s)) s = ewc->getSubExpr();
  const Expr* lhs = nullptr;
  if (auto* bo = dyn_cast_or_null<BinaryOperator>(s); bo && bo->isAssignmentOp()) lhs = bo->getLHS();
  if (auto* op = dyn_cast_or_null<CXXOperatorCallExpr>(s); op && (op->isAssignmentOp() || op->getOperator() == OO_PlusPlus ||
                                                                   op->getOperator() == OO_MinusMinus))
    lhs = op->getArg(0);
  if (auto* uo = dyn_cast_or_null<UnaryOperator>(s); uo && uo->isIncrementDecrementOp()) lhs = uo->getSubExpr();
  const FieldDecl* f = lhs ? ThisField(lhs) : nullptr;
  const Member* m = f ? FindMember(m_c.model, f->getNameAsString()) : nullptr;
  if (!m || m->kind != MemberKind::Plain || !m->inClassData) return;
  SourceLocation end = Lexer::findLocationAfterToken(s->getEndLoc(), tok::semi, m_c.ctx.getSourceManager(), m_c.ctx.getLangOpts(), false);
  if (end.isInvalid()) return;
  m_gpu.InsertTextAfter(end, " crt_UpdateMemberCmd(crt_cmd, offsetof(ClassData, " + m->name + "), &" + m->name + ", sizeof(" + m->name + "));");
}

bool ControlRewriter::IsWholeVector(const CallExpr* call) {
  auto* first = dyn_cast<CXXMemberCallExpr>(call->getArg(0)->IgnoreParenImpCasts());
  auto* last = dyn_cast<CXXMemberCallExpr>(call->getArg(1)->IgnoreParenImpCasts());
  if (!first || !last || !first->getMethodDecl() || !last->getMethodDecl()) return false;
  auto* f = ThisField(first->getImplicitObjectArgument());
  return f && f == ThisField(last->getImplicitObjectArgument()) && first->getMethodDecl()->getName() == "begin" &&
         last->getMethodDecl()->getName() == "end";
}

void ControlRewriter::CheckAppendedUses() {
  struct Finder : RecursiveASTVisitor<Finder> {
    ControlRewriter& rw;
    std::set<const Expr*> sortBounds;  // begin() and end() of whole-vector std::sort calls
    explicit Finder(ControlRewriter& r) : rw(r) {}
    bool VisitCallExpr(CallExpr* call) {
      auto* fd = call->getDirectCallee();
      if (fd && fd->isInStdNamespace() && fd->getName() == "sort" && call->getNumArgs() >= 2 && IsWholeVector(call)) {
        sortBounds.insert(call->getArg(0)->IgnoreParenImpCasts());
        sortBounds.insert(call->getArg(1)->IgnoreParenImpCasts());
      }
      return true;
    }
    void Check(const Expr* object, const std::string& what, SourceLocation loc) {
      auto* f = ThisField(object);
      if (!f || !rw.m_c.appended.count(f->getNameAsString())) return;
      const std::string v = f->getNameAsString();
      rw.m_c.rep.RecordingError(loc, "control function '" + rw.m_ctrl.name + "' uses " + what + " of '" + v +
                             "', which kernels append to: on the GPU its size and contents are known only after the call returns",
                             "loop to " + v + ".size() inside a kernel1D_ kernel (dispatched indirectly, with no host round trip), or read " + v +
                             " after the call; here it may only be cleared, reserved, or sorted whole with std::sort(" + v + ".begin(), " + v + ".end(), ...)");
    }
    bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
      static const std::set<std::string> allowed = {"clear", "reserve", "capacity", "data"};
      std::string method = call->getMethodDecl() ? call->getMethodDecl()->getNameAsString() : "";
      if (!allowed.count(method) && !sortBounds.count(call)) Check(call->getImplicitObjectArgument(), method + "()", call->getExprLoc());
      return true;
    }
    bool VisitCXXOperatorCallExpr(CXXOperatorCallExpr* op) {
      if (op->getOperator() == OO_Subscript) Check(op->getArg(0), "operator[]", op->getExprLoc());
      return true;
    }
  } finder(*this);
  finder.TraverseStmt(const_cast<Stmt*>(m_def->getBody()));
}

void ControlRewriter::RecordClear(const Stmt* s) {
  auto* call = dyn_cast_or_null<CXXMemberCallExpr>(s);
  if (!call || !call->getMethodDecl() || call->getMethodDecl()->getName() != "clear") return;
  auto* f = ThisField(call->getImplicitObjectArgument());
  if (!f || !m_c.appended.count(f->getNameAsString())) return;
  SourceLocation end = Lexer::findLocationAfterToken(s->getEndLoc(), tok::semi, m_c.ctx.getSourceManager(), m_c.ctx.getLangOpts(), false);
  if (end.isInvalid()) return;
  const std::string size = generated::SizeField(f->getNameAsString());
  m_gpu.InsertTextBefore(s->getBeginLoc(), "{ ");
  m_gpu.InsertTextAfter(end, " const uint32_t crt_empty = 0; crt_UpdateMemberCmd(crt_cmd, offsetof(ClassData, " + size +
                                 "), &crt_empty, sizeof(crt_empty)); }");
}

void ControlRewriter::CheckNestedControl(const CXXMemberCallExpr* call) {
  auto* md = call->getMethodDecl();
  const FunctionDecl* def = nullptr;
  if (!md || IsKernelName(md->getName()) || !md->hasBody(def) || !def || !IsClassOrBase(md->getParent(), m_c.cls) ||
      IsPerThreadFunction(md, m_c.cls))
    return;
  KernelCallFinder kc(m_c.cls);
  kc.TraverseStmt(def->getBody());
  if (kc.calls.empty()) return;
  m_c.rep.RecordingError(call->getBeginLoc(), "control function '" + m_ctrl.name + "' calls control function '" + md->getNameAsString() + "'",
                      "on the GPU each control function is one submission: call its kernels directly here, or call both from outside the class");
}

void ControlRewriter::Visit(const Stmt* s) {
  if (!s) return;
  // Statement positions where a member may be assigned.
  if (auto* cs = dyn_cast<CompoundStmt>(s))
    for (auto* child : cs->body()) RecordMemberWrite(child);
  if (auto* is = dyn_cast<IfStmt>(s)) {
    RecordMemberWrite(is->getThen());
    RecordMemberWrite(is->getElse());
  }
  if (auto* fs = dyn_cast<ForStmt>(s)) RecordMemberWrite(fs->getBody());
  if (auto* ws = dyn_cast<WhileStmt>(s)) RecordMemberWrite(ws->getBody());
  if (auto* ds = dyn_cast<DoStmt>(s)) RecordMemberWrite(ds->getBody());
  if (auto* mc = dyn_cast<CXXMemberCallExpr>(s)) CheckNestedControl(mc);
  if (auto* call = dyn_cast<CallExpr>(s); call && TrySwap(call)) return;
  if (auto* call = dyn_cast<CallExpr>(s); call && !isa<CXXMemberCallExpr>(s) && TryLibraryCall(call)) return;
  if (auto* fs = dyn_cast<ForStmt>(s); fs && (TryThreadLoop(fs) || TryRtvNest(fs))) return;
  if (auto* call = dyn_cast<CXXMemberCallExpr>(s)) {
    auto* md = call->getMethodDecl();
    if (md && IsKernelName(md->getName()) && isa<CXXThisExpr>(call->getImplicitObjectArgument()->IgnoreParenImpCasts())) {
      if (!IpvDims(md->getName())) {
        m_c.rep.GpuError(call->getBeginLoc(), "kernel '" + md->getNameAsString() + "' must be called inside loops over its thread ids",
                      "call it as: for (int i = 0; i < n; i++) " + md->getNameAsString() + "(i, ...);");
        return;
      }
      Note(call);
      // An argument reads a member the kernels before it write: run those first (HostReads.cpp).
      const std::string sync = m_syncCalls.count(call) ? "crt_Synchronize(crt_cmd, \"" + m_ctrl.name + "\"), " : "";
      m_gpu.ReplaceText(call->getSourceRange(), sync + md->getNameAsString() + "Cmd(crt_cmd" + Args(call, false) + ")");
      return;
    }
  }
  for (auto* child : s->children()) Visit(child);
}

}  // namespace crossrt::engine
