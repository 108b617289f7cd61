// Questions the passes ask of Clang's AST: source text and files of declarations, the member or
// variable an expression names or writes, a class's fields and methods (bases first), and which
// functions push_back to member vectors. Takes AST nodes, gives answers; changes nothing.
#include "analyse/AstQueries.h"

#include <algorithm>
#include <cctype>
#include <regex>

using namespace clang;

namespace crossrt::engine {

std::string BaseName(const std::string& path) {
  auto pos = path.find_last_of('/');
  return pos == std::string::npos ? path : path.substr(pos + 1);
}

std::string Text(const ASTContext& ctx, SourceRange range) {
  auto& sm = ctx.getSourceManager();
  CharSourceRange r = CharSourceRange::getTokenRange(sm.getExpansionRange(range).getAsRange());
  return Lexer::getSourceText(r, sm, ctx.getLangOpts()).str();
}

std::string FileOf(const ASTContext& ctx, SourceLocation loc) {
  auto& sm = ctx.getSourceManager();
  auto entry = sm.getFileEntryRefForID(sm.getFileID(sm.getExpansionLoc(loc)));
  return entry ? entry->getName().str() : std::string();
}

SourcePlace PlaceOf(const ASTContext& ctx, SourceLocation loc) {
  auto& sm = ctx.getSourceManager();
  const SourceLocation at = sm.getExpansionLoc(loc);
  return {FileOf(ctx, at), sm.getExpansionLineNumber(at), sm.getExpansionColumnNumber(at)};
}

namespace {

// "[[crossrt::size("n")]] const float* in" -> "const float* in"
std::string StripAttributes(std::string s) {
  static const std::regex cxx11(R"(\[\[[^\]]*\]\]\s*)");
  static const std::regex gnu(R"(__attribute__\s*\(\((?:[^()]|\((?:[^()]|\([^()]*\))*\))*\)\)\s*)");
  s = std::regex_replace(s, cxx11, "");
  s = std::regex_replace(s, gnu, "");
  while (!s.empty() && isspace((unsigned char)s.back())) s.pop_back();
  return s;
}

}  // namespace

std::string ParamDecl(const ASTContext& ctx, const ParmVarDecl* p, unsigned index) {
  std::string name = p->getNameAsString();
  if (name.empty()) return p->getType().getAsString(ctx.getPrintingPolicy()) + " a_unnamed" + std::to_string(index);
  SourceRange range(p->getBeginLoc(), p->getLocation());
  return StripAttributes(Text(ctx, range));
}

std::string ParamDecl(const ASTContext& ctx, const ParmVarDecl* p, const ParmVarDecl* named, unsigned index) {
  std::string text = ParamDecl(ctx, p, index);
  const std::string from = p->getName().empty() ? "a_unnamed" + std::to_string(index) : p->getNameAsString(), to = named->getNameAsString();
  if (!to.empty() && to != from && text.size() >= from.size() && text.compare(text.size() - from.size(), from.size(), from) == 0)
    text = text.substr(0, text.size() - from.size()) + to;
  return text;
}

std::string CppTypeName(const ASTContext& ctx, QualType t) {
  PrintingPolicy pp(ctx.getLangOpts());
  pp.SuppressTagKeyword = true;
  pp.FullyQualifiedName = true;
  pp.PrintCanonicalTypes = false;
  return t.getUnqualifiedType().getAsString(pp);
}

const FieldDecl* ThisField(const Expr* e) {
  auto* me = dyn_cast<MemberExpr>(e->IgnoreParenImpCasts());
  if (!me || !isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts())) return nullptr;
  return dyn_cast<FieldDecl>(me->getMemberDecl());
}

// The initialiser a local reference `T& r = init;` names, or null for anything else. Kernels print
// r as init (KernelPrinter::ReferenceAlias), so what is written through r is written to init's root.
static const Expr* ReferredTo(const Expr* e) {
  auto* dr = dyn_cast<DeclRefExpr>(e);
  auto* vd = dr ? dyn_cast<VarDecl>(dr->getDecl()) : nullptr;
  if (!vd || isa<ParmVarDecl>(vd) || !vd->getType()->isReferenceType() || !vd->hasLocalStorage() || !vd->getInit()) return nullptr;
  return vd->getInit();
}

const FieldDecl* RootField(const Expr* e) {
  while (true) {
    e = e->IgnoreParenImpCasts();
    if (auto* f = ThisField(e)) return f;
    if (const Expr* referred = ReferredTo(e)) { e = referred; continue; }
    if (auto* as = dyn_cast<ArraySubscriptExpr>(e)) { e = as->getBase(); continue; }
    if (auto* op = dyn_cast<CXXOperatorCallExpr>(e); op && op->getOperator() == OO_Subscript) { e = op->getArg(0); continue; }
    if (auto* me = dyn_cast<MemberExpr>(e)) { e = me->getBase(); continue; }
    return nullptr;
  }
}

const VarDecl* NamedVar(const clang::Expr* e) {
  for (;;) {
    e = e->IgnoreImplicit()->IgnoreParenImpCasts();
    auto* copy = dyn_cast<CXXConstructExpr>(e);
    if (!copy || copy->getNumArgs() != 1 || !copy->getConstructor()->isCopyOrMoveConstructor()) break;
    e = copy->getArg(0);
  }
  auto* ref = dyn_cast<DeclRefExpr>(e);
  return ref ? dyn_cast<VarDecl>(ref->getDecl()) : nullptr;
}

const VarDecl* WrittenVar(const clang::Expr* e) {
  for (;;) {
    e = e->IgnoreParenImpCasts();
    if (auto* me = dyn_cast<MemberExpr>(e)) e = me->getBase();
    else if (auto* sub = dyn_cast<ArraySubscriptExpr>(e)) e = sub->getBase();
    else if (auto* op = dyn_cast<CXXOperatorCallExpr>(e); op && (op->getOperator() == OO_Subscript || op->getOperator() == OO_Call)) e = op->getArg(0);
    else if (const Expr* referred = ReferredTo(e)) e = referred;
    else return NamedVar(e);
  }
}

std::vector<const FieldDecl*> ClassFields(const CXXRecordDecl* cls) {
  std::vector<const FieldDecl*> out;
  for (auto& base : cls->bases())
    if (auto* b = base.getType()->getAsCXXRecordDecl(); b && b->hasDefinition() && !base.isVirtual()) {
      auto inherited = ClassFields(b->getDefinition());
      out.insert(out.end(), inherited.begin(), inherited.end());
    }
  for (auto* f : cls->fields()) out.push_back(f);
  return out;
}

std::vector<const CXXMethodDecl*> ClassMethods(const CXXRecordDecl* cls) {
  std::vector<const CXXMethodDecl*> out;
  std::set<std::string> names;
  std::vector<const CXXRecordDecl*> order = {cls};
  for (size_t i = 0; i < order.size(); ++i)
    for (auto& base : order[i]->bases())
      if (auto* b = base.getType()->getAsCXXRecordDecl(); b && b->hasDefinition()) order.push_back(b->getDefinition());
  for (auto* rd : order) {
    std::set<std::string> here;
    for (auto* md : rd->methods()) {
      if (isa<CXXConstructorDecl, CXXDestructorDecl>(md) || names.count(md->getNameAsString())) continue;
      out.push_back(md);
      here.insert(md->getNameAsString());
    }
    names.insert(here.begin(), here.end());
  }
  return out;
}

bool InLiteMath(const Decl* d) {
  for (auto* dc = d->getDeclContext(); dc; dc = dc->getParent())
    if (auto* ns = dyn_cast<NamespaceDecl>(dc); ns && ns->getName() == "LiteMath") return true;
  return false;
}

bool IsClassOrBase(const CXXRecordDecl* rd, const CXXRecordDecl* cls) {
  return rd && (rd == cls || cls->isDerivedFrom(rd));
}

const FieldDecl* AppendTarget(const CXXMemberCallExpr* call) {
  auto* md = call->getMethodDecl();
  if (!md || md->getName() != "push_back") return nullptr;
  auto* f = ThisField(call->getImplicitObjectArgument());
  return f && IsStdVector(f->getType()) ? f : nullptr;
}

const VarDecl* AddressedVar(const Expr* arg) {
  auto* uo = dyn_cast<UnaryOperator>(arg->IgnoreParenImpCasts());
  auto* dr = uo && uo->getOpcode() == UO_AddrOf ? dyn_cast<DeclRefExpr>(uo->getSubExpr()->IgnoreParens()) : nullptr;
  return dr ? dyn_cast<VarDecl>(dr->getDecl()) : nullptr;
}

const FunctionDecl* ThisMethodDef(const CXXMemberCallExpr* call, const CXXRecordDecl* cls) {
  auto* md = call->getMethodDecl();
  const FunctionDecl* def = nullptr;
  if (!md || md->isStatic() || !IsClassOrBase(md->getParent(), cls) || !isa<CXXThisExpr>(call->getImplicitObjectArgument()->IgnoreParenImpCasts()))
    return nullptr;
  return md->hasBody(def) ? def : nullptr;
}

bool AppendsThroughCalls(const FunctionDecl* fn, const CXXRecordDecl* cls, std::map<const FunctionDecl*, bool>& memo) {
  if (auto it = memo.find(fn); it != memo.end()) return it->second;
  memo[fn] = false;  // a recursive call adds nothing (and is a diagnostic of its own)
  struct Finder : RecursiveASTVisitor<Finder> {
    const CXXRecordDecl* cls; std::map<const FunctionDecl*, bool>& memo; bool found = false;
    Finder(const CXXRecordDecl* c, std::map<const FunctionDecl*, bool>& m) : cls(c), memo(m) {}
    bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
      if (AppendTarget(call)) found = true;
      else if (auto* def = ThisMethodDef(call, cls)) found = found || AppendsThroughCalls(def, cls, memo);
      return !found;
    }
  } finder(cls, memo);
  finder.TraverseStmt(fn->getBody());
  return memo[fn] = finder.found;
}

bool ContainsCall(const Stmt* s) {
  struct Calls : RecursiveASTVisitor<Calls> {
    bool found = false;
    bool VisitCallExpr(CallExpr*) { found = true; return false; }
  } calls;
  calls.TraverseStmt(const_cast<Stmt*>(s));
  return calls.found;
}

bool Mentions(const Stmt* s, const Decl* d) {
  struct Refs : RecursiveASTVisitor<Refs> {
    const Decl* d; bool found = false;
    bool VisitDeclRefExpr(DeclRefExpr* dr) { found = dr->getDecl() == d; return !found; }
  } refs;
  refs.d = d;
  refs.TraverseStmt(const_cast<Stmt*>(s));
  return refs.found;
}

}  // namespace crossrt::engine
