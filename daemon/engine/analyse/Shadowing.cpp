// Locals that shadow a name: C++ lets a block declare `int n` inside a kernel whose parameter is n,
// or `float kEps` beside a namespace constant kEps. ISPC warns of every such shadowing (and so does
// -Wshadow of the C++ copies), and the generated code reads better without it, so such a local takes
// a suffix: n_1 (n_2 where it shadows an n_1, and so on, past any name the function already uses).
// The choice depends on the source alone, so it is the same in every backend and every regeneration.
#include "analyse/Shadowing.h"

#include <clang/AST/ExprCXX.h>
#include <clang/AST/ParentMapContext.h>
#include <clang/AST/StmtCXX.h>

#include <set>

using namespace clang;

namespace crossrt::engine {

namespace {

// The variables that `scope` declares for the statement `from` (one of its children) to see: a
// block's declarations before `from`, a loop's or a condition's own variables, a function's
// parameters.
void VisibleFrom(const DynTypedNode& scope, const DynTypedNode& from, std::vector<const VarDecl*>& out) {
  auto declsOf = [&out](const clang::Stmt* s) {
    if (auto* ds = dyn_cast_or_null<DeclStmt>(s))
      for (auto* d : ds->decls())
        if (auto* vd = dyn_cast<VarDecl>(d)) out.push_back(vd);
  };
  if (auto* cs = scope.get<CompoundStmt>()) {
    for (auto* child : cs->body()) {
      if (child == from.get<clang::Stmt>()) break;
      declsOf(child);
    }
  } else if (auto* fs = scope.get<ForStmt>()) {
    declsOf(fs->getInit());
    if (fs->getConditionVariable()) out.push_back(fs->getConditionVariable());
  } else if (auto* rf = scope.get<CXXForRangeStmt>()) {
    if (from.get<clang::Stmt>() == rf->getBody()) out.push_back(rf->getLoopVariable());
  } else if (auto* is = scope.get<IfStmt>()) {
    declsOf(is->getInit());
    if (is->getConditionVariable()) out.push_back(is->getConditionVariable());
  } else if (auto* ws = scope.get<WhileStmt>()) {
    if (ws->getConditionVariable()) out.push_back(ws->getConditionVariable());
  } else if (auto* ss = scope.get<SwitchStmt>()) {
    declsOf(ss->getInit());
    if (ss->getConditionVariable()) out.push_back(ss->getConditionVariable());
  } else if (auto* fd = scope.get<FunctionDecl>()) {
    for (auto* p : fd->parameters()) out.push_back(p);
  } else if (auto* lambda = scope.get<LambdaExpr>()) {
    for (auto* p : lambda->getCallOperator()->parameters()) out.push_back(p);
  }
}

// Every variable name a function body declares (the suffixed name must not be one of them).
void NamesIn(const clang::Stmt* s, std::set<std::string>& names) {
  if (!s) return;
  if (auto* ds = dyn_cast<DeclStmt>(s))
    for (auto* d : ds->decls())
      if (auto* nd = dyn_cast<NamedDecl>(d)) names.insert(nd->getNameAsString());
  for (auto* child : s->children()) NamesIn(child, names);
}

}  // namespace

std::string ShadowingLocalName(ASTContext& ctx, const VarDecl* vd) {
  const std::string name = vd->getNameAsString();
  if (isa<ParmVarDecl>(vd) || !vd->getDeclContext()->isFunctionOrMethod() || name.empty()) return "";
  // Up from the declaration to its function (a lambda is printed as a function of its own: its
  // body stops the walk too), counting the enclosing declarations of the same name.
  int shadowed = 0;
  const FunctionDecl* function = nullptr;
  DynTypedNode node = DynTypedNode::create(*vd);
  while (!function) {
    auto parents = ctx.getParents(node);
    if (parents.empty()) break;
    const DynTypedNode scope = parents[0];
    std::vector<const VarDecl*> visible;
    VisibleFrom(scope, node, visible);
    for (const VarDecl* other : visible)
      if (other != vd && other->getName() == vd->getName()) ++shadowed;
    if (auto* lambda = scope.get<LambdaExpr>()) function = lambda->getCallOperator();
    else function = scope.get<FunctionDecl>();
    node = scope;
  }
  // A constant of an enclosing namespace (an anonymous one, one named by `using namespace`) or of
  // the class, which the kernel may print as a global.
  std::vector<const DeclContext*> outer;
  for (const DeclContext* dc = vd->getDeclContext()->getParent(); dc; dc = dc->getParent()) {
    outer.push_back(dc);
    if (auto* tu = dyn_cast<TranslationUnitDecl>(dc); tu && tu->getAnonymousNamespace()) outer.push_back(tu->getAnonymousNamespace());
    if (auto* ns = dyn_cast<NamespaceDecl>(dc); ns && ns->getAnonymousNamespace()) outer.push_back(ns->getAnonymousNamespace());
    for (const UsingDirectiveDecl* ud : dc->using_directives()) outer.push_back(ud->getNominatedNamespace());
  }
  std::set<const VarDecl*> globals;  // (an anonymous namespace is reached twice: its implicit using-directive)
  for (const DeclContext* dc : outer)
    for (const NamedDecl* found : dc->lookup(vd->getDeclName()))
      if (auto* global = dyn_cast<VarDecl>(found); global && global->hasGlobalStorage()) globals.insert(global->getCanonicalDecl());
  shadowed += int(globals.size());
  if (shadowed == 0) return "";
  std::set<std::string> taken;
  if (function) {
    NamesIn(function->getBody(), taken);
    for (auto* p : function->parameters()) taken.insert(p->getNameAsString());
  }
  std::string renamed;
  for (int k = shadowed; renamed.empty() || taken.count(renamed); ++k) renamed = name + "_" + std::to_string(k);
  return renamed;
}

}  // namespace crossrt::engine
