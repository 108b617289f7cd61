// The driver's pass over one translation unit: finds the user's class by name, then runs the passes
// on what the unit defines (members once, then kernels, then control functions).

#include "analyse/AnalysisContext.h"
#include "analyse/AstQueries.h"
#include "analyse/BlockKernels.h"
#include "control/ControlFunctions.h"
#include "analyse/Kernels.h"
#include "analyse/Members.h"
#include "analyse/ReservedNames.h"
#include "analyse/Naming.h"

#include <llvm/Support/FileSystem.h>
#include <llvm/Support/Path.h>

#include <algorithm>
#include <regex>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

bool AnalyzeTranslationUnit(ASTContext& ctx, const IncludesSeen& includes, const std::string& className,
                            const std::map<std::string, std::string>& compositions, Reporter& reporter, ClassModel& model) {
  // Name lookups, namespace by namespace ("demo::Render"): walking every declaration of the
  // standard library would cost more than the rest of the analysis.
  std::vector<std::string> path;
  for (size_t start = 0;;) {
    const size_t colons = className.find("::", start);
    path.push_back(className.substr(start, colons == std::string::npos ? std::string::npos : colons - start));
    if (colons == std::string::npos) break;
    start = colons + 2;
  }
  const DeclContext* scope = ctx.getTranslationUnitDecl();
  for (size_t i = 0; i + 1 < path.size() && scope; ++i) {
    const DeclContext* inner = nullptr;
    for (auto* d : scope->lookup(&ctx.Idents.get(path[i])))
      if (auto* ns = dyn_cast<NamespaceDecl>(d)) inner = ns;
    scope = inner;
  }
  const CXXRecordDecl* cls = nullptr;
  if (scope && !path.back().empty())
    for (auto* d : scope->lookup(&ctx.Idents.get(path.back())))
      if (auto* rd = dyn_cast<CXXRecordDecl>(d); rd && rd->getDefinition()) cls = rd->getDefinition();
  if (!cls) return false;
  Context c{ctx, cls, reporter, model, compositions, {}, {}};
  bool first = model.className.empty();
  if (first) {
    model.className = path.back();
    for (size_t i = 0; i + 1 < path.size(); ++i) model.namespaceName += (i ? "::" : "") + path[i];
    model.headerFile = FileOf(ctx, cls->getLocation());
    AnalyzeMembers(c);
  }
  CheckReservedNames(c, first);
  // Locals a control function passes to kernels by address are per-thread values on the GPU: find
  // them before analysing the kernels, whose GLSL signatures they change.
  {
    struct LocalAddressFinder : RecursiveASTVisitor<LocalAddressFinder> {
      std::set<std::pair<std::string, std::string>>& out;
      explicit LocalAddressFinder(std::set<std::pair<std::string, std::string>>& o) : out(o) {}
      bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
        auto* md = call->getMethodDecl();
        if (!md || !IsKernelName(md->getName()) || IpvDims(md->getName())) return true;
        for (unsigned i = 0; i < call->getNumArgs() && i < md->getNumParams(); ++i) {
          auto* vd = AddressedVar(call->getArg(i));
          if (vd && vd->hasLocalStorage() && !isa<ParmVarDecl>(vd)) out.insert({md->getNameAsString(), md->getParamDecl(i)->getNameAsString()});
        }
        return true;
      }
    } finder(c.threadState);
    for (auto* md : ClassMethods(cls)) {
      const FunctionDecl* def = nullptr;
      if (!IsKernelName(md->getName()) && md->hasBody(def) && def) finder.TraverseStmt(def->getBody());
    }
  }
  // Appends decide how other kernels are dispatched: find them all before analysing any kernel.
  {
    AppendFinder finder(cls);
    for (auto* md : ClassMethods(cls)) {
      const FunctionDecl* def = nullptr;
      if (IsKernelName(md->getName()) && md->hasBody(def) && def) finder.TraverseStmt(def->getBody());
    }
    for (auto& m : model.members)
      if (m.appendedByKernels) finder.appended.insert(m.name);  // found in another source file
    c.appended = finder.appended;
  }
  auto known = [](const auto& list, const std::string& n) {
    return std::any_of(list.begin(), list.end(), [&](const auto& x) { return x.name == n; });
  };
  // #include lines of the source file: bodies copied from it rely on them. Quoted includes are
  // respelled so they resolve from the build tree.
  {
    auto& sm = ctx.getSourceManager();
    StringRef buffer = sm.getBufferData(sm.getMainFileID());
    static const std::regex inc(R"(^[ \t]*#[ \t]*include[ \t]*([<"])([^>"]+)[>"])");
    std::string dir = llvm::sys::path::parent_path(FileOf(ctx, sm.getLocForStartOfFile(sm.getMainFileID()))).str();
    std::istringstream lines(buffer.str());
    unsigned lineNumber = 0;
    for (std::string line; std::getline(lines, line);) {
      ++lineNumber;
      std::smatch m;
      if (!std::regex_search(line, m, inc)) continue;
      std::string text;
      if (m[1] == "<") text = "#include <" + m[2].str() + ">";
      else {
        std::string path = dir + "/" + m[2].str();
        if (!llvm::sys::fs::exists(path) && includes.mainFile.count(lineNumber)) path = includes.mainFile.at(lineNumber);  // found through an include directory
        else if (!llvm::sys::fs::exists(path))  // read before, through another include: the file of that name
          for (auto& name : includes.files)
            if (StringRef(name).ends_with("/" + m[2].str())) path = name;
        if (path == model.headerFile) continue;  // the generated header includes it already
        text = "#include \"" + path + "\"";
      }
      if (std::find(model.sourceIncludes.begin(), model.sourceIncludes.end(), text) == model.sourceIncludes.end())
        model.sourceIncludes.push_back(text);
    }
  }
  // using-directives at the top level of the source file: bodies copied from it rely on them.
  for (auto* d : ctx.getTranslationUnitDecl()->decls()) {
    auto& sm = ctx.getSourceManager();
    if (!isa<UsingDirectiveDecl, UsingDecl>(d) || !sm.isInMainFile(sm.getExpansionLoc(d->getLocation()))) continue;
    std::string text = c.Text(d->getSourceRange()) + ";";
    if (std::find(model.usingDecls.begin(), model.usingDecls.end(), text) == model.usingDecls.end()) model.usingDecls.push_back(text);
  }
  AnalyzeBlockKernels(c);  // kernel_slicer's kernelBE1D_ (often templates, which the methods below do not list)
  // Kernels first: control functions refer to them.
  for (int pass = 0; pass < 2; ++pass) {
    for (auto* md : ClassMethods(cls)) {
      const FunctionDecl* def = nullptr;
      if (!md->hasBody(def) || !def) continue;
      // A method defined in a header is seen by every source file: analyse it once.
      std::string n = md->getNameAsString();
      bool isKernel = IsKernelName(n);
      if (pass == 0 && isKernel && !known(model.kernels, n)) AnalyzeKernel(c, md, def);
      if (pass == 1 && !isKernel && !known(model.controls, n) && !IsPerThreadFunction(md, cls)) {  // those run inside thread loops
        KernelCallFinder kc(cls);
        kc.TraverseStmt(def->getBody());
        if (!kc.calls.empty()) AnalyzeControl(c, md, def);
      }
    }
  }
  return true;
}

}  // namespace crossrt::engine
