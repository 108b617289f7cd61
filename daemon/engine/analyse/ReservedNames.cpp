// User names under the generated code's prefix crt_ are errors (ReservedNames.h).
#include "analyse/ReservedNames.h"

#include "analyse/AstQueries.h"

#include <clang/AST/RecursiveASTVisitor.h>

namespace crossrt::engine {

namespace {

bool Reserved(llvm::StringRef name) { return name.starts_with("crt_"); }

void Report(Context& c, SourceLocation at, const std::string& what, llvm::StringRef name) {
  c.rep.Error(at, what + " '" + name.str() + "' begins with crt_, which CrossRT keeps for the names of the code it generates",
              "rename it: a generated name could take its place without a word");
}

struct BodyNames : RecursiveASTVisitor<BodyNames> {
  Context& c;
  explicit BodyNames(Context& context) : c(context) {}
  bool VisitVarDecl(VarDecl* vd) {
    if (Reserved(vd->getName())) Report(c, vd->getLocation(), isa<ParmVarDecl>(vd) ? "parameter" : "variable", vd->getName());
    return true;
  }
};

}  // namespace

void CheckReservedNames(Context& c, bool declarations) {
  const SourceManager& sm = c.ctx.getSourceManager();
  if (declarations) {
    for (const FieldDecl* f : c.cls->fields())
      if (Reserved(f->getName())) Report(c, f->getLocation(), "data member", f->getName());
    for (const CXXMethodDecl* md : c.cls->methods()) {
      if (md->isImplicit()) continue;
      if (md->getIdentifier() && Reserved(md->getName())) Report(c, md->getLocation(), "member function", md->getName());
      for (const ParmVarDecl* p : md->parameters())
        if (Reserved(p->getName())) Report(c, p->getLocation(), "parameter", p->getName());
    }
  }
  BodyNames bodies(c);
  for (const CXXMethodDecl* md : c.cls->methods()) {
    const FunctionDecl* def = nullptr;
    if (!md->hasBody(def) || !def || !def->getBody()) continue;
    // A body in a header is seen by every source file: checked with the declarations, once.
    const bool inThisSource = sm.isInMainFile(sm.getExpansionLoc(def->getLocation()));
    if (!inThisSource && !declarations) continue;
    for (const ParmVarDecl* p : def->parameters())
      if (def != md && Reserved(p->getName())) Report(c, p->getLocation(), "parameter", p->getName());
    bodies.TraverseStmt(def->getBody());
  }
}

}  // namespace crossrt::engine
