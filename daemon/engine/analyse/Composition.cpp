// Composition (paper 3.6): a member of an interface type with an implementation given by COMPOSE. The
// implementation's methods that kernels call are printed into the kernels, its data becomes buffers and
// class data reached through the holder. Takes the implementation's AST; adds to the kernels.
#include "analyse/Composition.h"

#include "analyse/AstQueries.h"
#include "analyse/Callables.h"
#include "analyse/LeafShaders.h"
#include "analyse/Members.h"
#include "analyse/VirtualCalls.h"
#include "analyse/WriteVisitor.h"
#include "print/Printers.h"

#include <algorithm>

using namespace clang;

namespace crossrt::engine {

const CXXMethodDecl* ImplementationOf(const CXXRecordDecl* impl, const std::string& name, const FunctionDecl*& def) {
  for (auto* d : impl->lookup(&impl->getASTContext().Idents.get(name)))
    if (auto* md = dyn_cast<CXXMethodDecl>(d); md && !md->isPureVirtual() && md->hasBody(def) && def) return md;
  for (auto& base : impl->bases())
    if (auto* rd = base.getType()->getAsCXXRecordDecl(); rd && rd->hasDefinition())
      if (auto* md = ImplementationOf(rd->getDefinition(), name, def)) return md;
  return nullptr;
}

namespace {

// The writes the finders below share: assignments, increments and decrements, built in or
// overloaded. Derived::Written(target, loc) decides what each write means to it.
// Writes to members of `this` in composed code: the GPU copy of an implementation's data is never
// read back, so such a write would be lost silently.
struct ComposedWriteFinder : WriteVisitor<ComposedWriteFinder> {
  std::vector<std::pair<const FieldDecl*, SourceLocation>> writes;
  void Written(const Expr* target, SourceLocation loc) {
    if (auto* f = RootField(target)) writes.push_back({f, loc});
  }
  bool VisitCallExpr(CallExpr* call) {
    if (IsCrossrtAtomic(call->getDirectCallee()) && call->getNumArgs() > 0) Written(call->getArg(0), call->getExprLoc());
    return true;
  }
};

}  // namespace

bool ComposeFromTranslationUnit(ASTContext& ctx, Reporter& reporter, ClassModel& model) {
  bool any = false;
  const std::set<std::string> classStructs = ClassStructNames(model);
  for (auto& comp : model.compositions) {
    if (!comp.implHeader.empty() || comp.implName.empty()) continue;
    const CXXRecordDecl* impl = nullptr;
    for (auto* d : ctx.getTranslationUnitDecl()->lookup(&ctx.Idents.get(comp.implName)))
      if (auto* rd = dyn_cast<CXXRecordDecl>(d); rd && rd->getDefinition()) impl = rd->getDefinition();
    if (!impl) continue;
    // Every method the kernels call must have its body here (the implementation's own source).
    bool complete = true;
    for (auto& k : model.kernels)
      for (auto& [holder, method] : k.composedCalls) {
        const FunctionDecl* def = nullptr;
        if (holder == comp.holder && !ImplementationOf(impl, method, def)) complete = false;
      }
    if (!complete) continue;
    any = true;
    comp.implHeader = FileOf(ctx, impl->getLocation());
    std::string holderPrefix = comp.holder + "_";
    for (auto& k : model.kernels) {
      std::unique_ptr<KernelPrinter> implPrinter = MakePrinter(model, ctx, impl, reporter);
      KernelPrinter& printer = *implPrinter;
      printer.dataStruct = model.symbolPrefix + "_Data";
      printer.composedPrefix = holderPrefix;
      for (auto& s : classStructs) printer.predeclaredStructs.insert(s);
      for (auto& [holder, method] : k.composedCalls) {
        if (holder != comp.holder) continue;
        const FunctionDecl* def = nullptr;
        auto* md = ImplementationOf(impl, method, def);
        printer.EmitComposedMethod(md);
      }
      if (printer.Functions().empty()) continue;
      // Virtual calls in the composed code (listing 2: an intersection function per primitive):
      // their dispatchers and the implementations' code go ahead of it.
      std::vector<GlslDecl> virtualStructs;
      std::vector<std::string> virtualFunctions;
      if (!printer.Uses().virtualCalls.empty())
        VirtualCallCode(ctx, reporter, model, k, printer, VirtualOwner{impl, holderPrefix, "crt_" + comp.holder + "()->", comp.holder}, virtualStructs,
                        virtualFunctions);
      CheckObjectSizeReads(reporter, printer);
      for (auto* fn : printer.Uses().helpers) {
        ComposedWriteFinder finder;
        finder.TraverseStmt(fn->getBody());
        for (auto& [field, loc] : finder.writes)
          reporter.GpuError(loc, "composed code writes member '" + field->getNameAsString() + "' of " + comp.implName +
                         ", whose GPU copy is never read back", "members of a composed implementation are read-only in kernels: compute into a local variable");
      }
      // The implementation's data: its std::vector members become buffers, plain members join
      // the class data, all reached through the holder on the host.
      std::vector<std::string> vectors;
      for (auto* f : printer.Uses().memberVectors) {
        QualType elem;
        IsStdVector(f->getType(), &elem);
        printer.Type(elem, f->getLocation());
      }
      auto requirePublic = [&](const FieldDecl* f) {
        RequirePublicForComposition(reporter, f, comp.implName, " (" + comp.interfaceName + "=" + comp.implName + ")");
      };
      for (auto* f : printer.Uses().memberVectors) {
        requirePublic(f);
        QualType elem;
        IsStdVector(f->getType(), &elem);
        std::string name = holderPrefix + f->getNameAsString();
        vectors.push_back(name);
        if (FindMember(model, name)) continue;
        Member m;
        m.name = name;
        m.hostExpr = "crt_" + comp.holder + "()->" + f->getNameAsString();
        m.composedFrom = comp.implName + "::" + f->getNameAsString() + " through " + comp.holder;
        m.kind = MemberKind::Vector;
        m.glslType = GlslTypeOf(elem).value_or("float");
        m.elemCppType = CppTypeName(ctx, elem);
        m.cppType = CppTypeName(ctx, f->getType());
        m.scalarLayout = !LayoutMatchesCpp(ctx, elem, false);
        if (m.scalarLayout && !LayoutMatchesCpp(ctx, elem, true))
          reporter.GpuError(f->getLocation(), "the elements of '" + f->getNameAsString() + "' have a C++ layout that a GPU buffer cannot reproduce",
                         "use int instead of bool, and 32-bit scalars and LiteMath vectors in structs");
        m.usedByKernels = true;
        model.members.push_back(m);
      }
      for (auto* f : printer.Uses().plainMembers) {
        requirePublic(f);
        std::string name = holderPrefix + f->getNameAsString();
        if (FindMember(model, name)) continue;
        Member m;
        m.name = name;
        m.hostExpr = "crt_" + comp.holder + "()->" + f->getNameAsString();
        m.composedFrom = comp.implName + "::" + f->getNameAsString() + " through " + comp.holder;
        m.glslType = GlslTypeOf(f->getType()).value_or("float");
        m.cppType = CppTypeName(ctx, f->getType());
        m.inClassData = FitsClassData(ctx, f->getType());
        if (auto layout = Std430Layout(ctx, f->getType(), false)) m.std430Align = unsigned(layout->align);
        m.specialized = IsSpecializedMember(f) && CheckSpecialized(reporter, f);
        if (!m.inClassData && !m.specialized)
          reporter.GpuError(f->getLocation(), "member '" + f->getNameAsString() + "' of type '" + f->getType().getAsString(ctx.getPrintingPolicy()) +
                         "' has a C++ layout that a GPU buffer cannot reproduce",
                         "use int instead of bool, float4x4 instead of float3x3");
        m.usedByKernels = true;
        model.members.push_back(m);
      }
      // Composed code first: the kernel's own code calls it and may use its structs.
      std::vector<GlslDecl> structs = printer.Structs(), constants = printer.Constants();
      std::vector<std::string> functions;
      std::vector<std::string> own = printer.Functions();
      for (auto* list : {&virtualFunctions, &own})  // free functions several print are the same text: once
        for (auto& x : *list)
          if (std::find(functions.begin(), functions.end(), x) == functions.end()) functions.push_back(x);
      for (auto* list : {&virtualStructs, &k.structList})
        for (auto& chunk : *list) {
          auto same = std::find_if(structs.begin(), structs.end(), [&](const GlslDecl& x) { return x.name == chunk.name; });
          if (same == structs.end()) structs.push_back(chunk);
        }
      for (auto& line : k.constantList)
        if (std::find(constants.begin(), constants.end(), line) == constants.end()) constants.push_back(line);
      functions.insert(functions.end(), k.functionList.begin(), k.functionList.end());
      k.structList = structs;
      k.constantList = constants;
      k.functionList = functions;
      for (auto& v : vectors)
        if (std::find(k.memberVectors.begin(), k.memberVectors.end(), v) == k.memberVectors.end()) k.memberVectors.push_back(v);
      std::sort(k.memberVectors.begin(), k.memberVectors.end());
      // Ray queries on ISceneObject alone can also run on ray tracing hardware (a second shader).
      const bool onlyRayQueries = std::all_of(k.composedCalls.begin(), k.composedCalls.end(), [&](const auto& call) {
        return call.first == comp.holder && (call.second == "RayQuery_NearestHit" || call.second == "RayQuery_AnyHit");
      });
      // Not when the traversal calls virtual intersection functions: those become intersection shaders
      // of a ray tracing pipeline instead (AnalyzeLeafTraversal).
      if (comp.interfaceName == "ISceneObject" && onlyRayQueries && printer.Uses().virtualCalls.empty()) k.rayQueryHolder = comp.holder;
      // Virtual intersection functions called per leaf can run as intersection shaders (level 3).
      if (model.virtualLevel == 3 && !printer.Uses().virtualCalls.empty() && reporter.Errors() == 0)
        AnalyzeLeafTraversal(ctx, reporter, model, k, comp, impl, holderPrefix, printer);
    }
  }
  return any;
}

}  // namespace crossrt::engine
