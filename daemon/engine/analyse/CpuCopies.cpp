// The CPU class's copies of the user's code: declarations and macros a kernel's body needs copied
// next to it, and the helpers that push_back to member vectors rewritten to take a lock (AddLockedCopies).
#include "analyse/CpuCopies.h"

#include "analyse/AnalysisContext.h"
#include "analyse/AstQueries.h"

#include <algorithm>
#include <regex>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

namespace {

// Bodies copied into generated files (control functions, the CPU's loop nests) see the class's
// header, the sources' includes and using-directives, and what this collects: the declarations of
// the source file itself that they use (static and free helpers, constants, types), and those these
// use in turn. Functions and constants private to the file (static, inline, an anonymous namespace,
// const) are copied whole; a function the file exports is declared, so that calls link to it.
// A declaration's source text with its ';' where it has one (`struct S {...};`, `const int k = 2;`).
std::string DeclText(Context& c, const Decl* d) {
  auto& sm = c.ctx.getSourceManager();
  SourceLocation end = Lexer::findLocationAfterToken(d->getEndLoc(), tok::semi, sm, c.ctx.getLangOpts(), false);
  if (end.isValid()) return Lexer::getSourceText(CharSourceRange::getCharRange(sm.getExpansionLoc(d->getBeginLoc()), end), sm, c.ctx.getLangOpts()).str();
  return c.Text(d->getSourceRange());
}

// The #define lines of a file (with their continuation lines) whose names `code` uses, and those
// the definitions use in turn, in the file's order: (name, definition).
std::vector<std::pair<std::string, std::string>> UsedMacros(llvm::StringRef file, const std::string& code) {
  static const std::regex defineLine(R"(^[ \t]*#[ \t]*define[ \t]+([A-Za-z_][A-Za-z0-9_]*))");
  std::vector<std::pair<std::string, std::string>> defines;  // in the file's order
  std::istringstream lines(file.str());
  std::string line;
  std::smatch m;
  while (std::getline(lines, line)) {
    if (!std::regex_search(line, m, defineLine)) continue;
    const std::string name = m[1].str();  // before the continuation lines replace `line`
    std::string definition = line;
    while (!line.empty() && line.back() == '\\' && std::getline(lines, line)) definition += "\n" + line;
    defines.push_back({name, definition});
  }
  static const std::regex identifier(R"([A-Za-z_][A-Za-z0-9_]*)");
  std::set<std::string> used;
  std::vector<std::string> pending = {code};
  while (!pending.empty()) {
    const std::string text = pending.back();
    pending.pop_back();
    for (std::sregex_iterator it(text.begin(), text.end(), identifier), end; it != end; ++it)
      for (auto& [name, definition] : defines)
        if (name == it->str() && used.insert(name).second) pending.push_back(definition.substr(definition.find(name) + name.size()));
  }
  std::vector<std::pair<std::string, std::string>> out;
  for (auto& d : defines)
    if (used.count(d.first)) out.push_back(d);
  return out;
}

}  // namespace

void CopySourceDeclarations(Context& c, const Stmt* body, const std::string& what) {
  auto& sm = c.ctx.getSourceManager();
  struct Finder : RecursiveASTVisitor<Finder> {
    Context& c; SourceManager& sm; const std::string& what;
    std::set<const Decl*> found;
    std::vector<const Decl*> pending;
    Finder(Context& ctx, SourceManager& m, const std::string& w) : c(ctx), sm(m), what(w) {}
    // The declaration of the main file a use refers to, at namespace scope, or null.
    const Decl* FileLevel(const Decl* d) {
      if (!d || isa<ParmVarDecl, FieldDecl, CXXMethodDecl>(d) || d->getDeclContext()->isFunctionOrMethod() || d->getDeclContext()->isRecord()) return nullptr;
      if (d->isImplicit()) return nullptr;  // a builtin (__builtin_ctz), declared where the file first calls it
      if (auto* vd = dyn_cast<VarDecl>(d); vd && vd->isLocalVarDeclOrParm()) return nullptr;
      if (auto* fd = dyn_cast<FunctionDecl>(d)) {
        if (auto* pattern = fd->getTemplateInstantiationPattern()) fd = pattern;
        const FunctionDecl* def = nullptr;
        d = fd->hasBody(def) && def ? def : fd;
        if (auto* tmpl = cast<FunctionDecl>(d)->getDescribedFunctionTemplate()) d = tmpl;
      }
      return sm.isInMainFile(sm.getExpansionLoc(d->getLocation())) ? d : nullptr;
    }
    void Use(const Decl* d) {
      d = FileLevel(d);
      if (d && found.insert(d).second) pending.push_back(d);
    }
    bool VisitDeclRefExpr(DeclRefExpr* e) { Use(e->getDecl()); return true; }
    bool VisitCallExpr(CallExpr* call) { Use(call->getCalleeDecl()); return true; }
    bool VisitTypeLoc(TypeLoc tl) {
      if (auto* tag = tl.getType()->getAsTagDecl()) Use(tag);
      if (auto* td = tl.getType()->getAs<TypedefType>()) Use(td->getDecl());
      return true;
    }
  } finder(c, sm, what);
  finder.TraverseStmt(const_cast<Stmt*>(body));
  while (!finder.pending.empty()) {  // what the collected declarations use, in turn
    const Decl* d = finder.pending.back();
    finder.pending.pop_back();
    finder.TraverseDecl(const_cast<Decl*>(d));
  }
  // In the order of the source file, each in its namespaces.
  std::vector<const Decl*> decls(finder.found.begin(), finder.found.end());
  std::sort(decls.begin(), decls.end(), [&](const Decl* a, const Decl* b) {
    return sm.isBeforeInTranslationUnit(sm.getExpansionLoc(a->getBeginLoc()), sm.getExpansionLoc(b->getBeginLoc()));
  });
  const std::string file = BaseName(FileOf(c.ctx, body->getBeginLoc()));
  for (const Decl* d : decls) {
    std::string text;
    const auto* fd = dyn_cast<FunctionDecl>(d);
    if (auto* tmpl = dyn_cast<FunctionTemplateDecl>(d)) fd = tmpl->getTemplatedDecl();
    if (fd && !isa<FunctionTemplateDecl>(d) && fd->isExternallyVisible() && !fd->isInlined() && fd->hasBody()) {
      // Exported by the source file: a declaration links to it (a copy would be defined twice).
      text = c.Text(SourceRange(fd->getBeginLoc(), fd->getBody()->getBeginLoc().getLocWithOffset(-1))) + ";";
    } else if (auto* vd = dyn_cast<VarDecl>(d); vd && !vd->getType().isConstQualified()) {
      if (!vd->isExternallyVisible()) {
        c.rep.Error(vd->getLocation(), "'" + vd->getNameAsString() + "' is a variable private to " + file + ", which " + what +
                    " uses; the generated class's copy of it would have a variable of its own", "make it const (or constexpr), or a member of the class");
        continue;
      }
      text = "extern " + c.Text(SourceRange(vd->getBeginLoc(), vd->getLocation())) + ";";
    } else {
      text = DeclText(c, d);
    }
    std::string open, close;
    for (auto* dc = d->getDeclContext(); dc && !dc->isTranslationUnit(); dc = dc->getParent())
      if (auto* ns = dyn_cast<NamespaceDecl>(dc)) {
        open = "namespace " + (ns->isAnonymousNamespace() ? std::string() : ns->getNameAsString() + " ") + "{ " + open;
        close += " }";
      }
    const std::string copy = "// from " + file + "\n" + CanonicalCode(open + text + close);
    if (std::find(c.model.sourceDecls.begin(), c.model.sourceDecls.end(), copy) == c.model.sourceDecls.end()) c.model.sourceDecls.push_back(copy);
  }
  // The file's macros the copied code expands (#define INCREMENT(a, b) a++; b++), ahead of the copies.
  std::string copiedText = c.Text(body->getSourceRange());
  for (const Decl* d : decls) copiedText += "\n" + c.Text(d->getSourceRange());
  const FileID fid = sm.getFileID(sm.getExpansionLoc(body->getBeginLoc()));
  size_t at = 0;  // after the macros copied so far
  while (at < c.model.sourceDecls.size() && c.model.sourceDecls[at].find("\n#define ") != std::string::npos) ++at;
  for (auto& [name, definition] : UsedMacros(sm.getBufferData(fid), copiedText)) {
    const std::string copy = "// from " + file + "\n" + definition;
    if (std::find(c.model.sourceDecls.begin(), c.model.sourceDecls.end(), copy) == c.model.sourceDecls.end())
      c.model.sourceDecls.insert(c.model.sourceDecls.begin() + at++, copy);
  }
}

void LockAppends(Rewriter& rw, const Stmt* body) {
  struct Locker : RecursiveASTVisitor<Locker> {
    Rewriter& rw;
    explicit Locker(Rewriter& r) : rw(r) {}
    bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
      if (!AppendTarget(call)) return true;
      SourceRange object = call->getImplicitObjectArgument()->getSourceRange();
      rw.InsertTextBefore(object.getBegin(), "crossrt::Locked(");
      rw.InsertTextAfterToken(object.getEnd(), ")");
      return true;
    }
  } locker(rw);
  locker.TraverseStmt(const_cast<Stmt*>(body));
}

void AddLockedCopies(Context& c, const std::vector<const FunctionDecl*>& reached) {
  std::map<const FunctionDecl*, bool> memo;
  for (auto* fn : reached) {
    auto* md = dyn_cast<CXXMethodDecl>(fn);
    if (!md || !IsClassOrBase(md->getParent(), c.cls) || md->isStatic() || !AppendsThroughCalls(fn, c.cls, memo)) continue;
    const std::string name = md->getNameAsString();
    const CXXMethodDecl* decl = cast<CXXMethodDecl>(md->getCanonicalDecl());
    LockedCopy copy;
    copy.name = name;
    copy.sourceFile = BaseName(FileOf(c.ctx, fn->getLocation()));
    std::string params, defParams;
    for (unsigned i = 0; i < decl->getNumParams(); ++i) {
      auto* p = decl->getParamDecl(i);
      params += (i ? ", " : "") + ParamDecl(c.ctx, p, i);
      if (p->hasDefaultArg() && !p->hasUninstantiatedDefaultArg() && !p->hasUnparsedDefaultArg())
        params += " = " + c.Text(p->getDefaultArgRange());
      defParams += (i ? ", " : "") + ParamDecl(c.ctx, md->getParamDecl(i), i);
    }
    const std::string ret = c.Text(decl->getReturnTypeSourceRange()), cv = md->isConst() ? " const" : "";
    copy.declaration = ret + " " + name + "(" + params + ")" + cv + (md->isVirtual() ? " override" : "");
    if (std::any_of(c.model.lockedCopies.begin(), c.model.lockedCopies.end(), [&](const LockedCopy& x) { return x.declaration == copy.declaration; }))
      continue;  // another kernel reached it first
    // The copy lives in the derived class: what it names must be reachable from there.
    struct PrivateUses : RecursiveASTVisitor<PrivateUses> {
      Context& c; const std::string& fn; std::set<const Decl*> reported;
      PrivateUses(Context& ctx, const std::string& f) : c(ctx), fn(f) {}
      bool VisitMemberExpr(MemberExpr* me) {
        auto* d = me->getMemberDecl();
        if (d->getAccess() != AS_private || d->getDeclContext() != c.cls || !reported.insert(d).second) return true;
        c.rep.Error(me->getMemberLoc(), "'" + fn + "' appends to a member vector, so the CPU backend copies it into the derived class, but it uses private member '" +
                    d->getNameAsString() + "'", "declare '" + d->getNameAsString() + "' protected");
        return true;
      }
    } privateUses(c, name);
    privateUses.TraverseStmt(fn->getBody());
    if (c.model.forCpu) CopySourceDeclarations(c, fn->getBody(), "'" + name + "', which appends,");
    // The copy hides every overload of its name: the others stay reachable through one
    // using-declaration, with the first copy of the name.
    auto overloads = c.cls->lookup(md->getDeclName());
    copy.keepOverloads = std::distance(overloads.begin(), overloads.end()) > 1 && decl->getAccess() != AS_private &&
                         std::none_of(c.model.lockedCopies.begin(), c.model.lockedCopies.end(), [&](const LockedCopy& x) { return x.name == name; });
    // Outside the class body a leading return type is looked up at namespace scope: a type
    // declared in the class goes after the name, where the class's scope applies.
    QualType rt = md->getReturnType();
    const NamedDecl* named = rt->getAsTagDecl();
    if (auto* td = rt->getAs<TypedefType>()) named = td->getDecl();
    const bool nested = named && named->getDeclContext() == c.cls;
    const std::string qualified = c.model.generatedName + "::" + name + "(" + defParams + ")" + cv;
    copy.definitionHead = nested ? "auto " + qualified + " -> " + ret : ret + " " + qualified;
    Rewriter rw(c.ctx.getSourceManager(), c.ctx.getLangOpts());
    LockAppends(rw, fn->getBody());
    copy.body = CanonicalCode(rw.getRewrittenText(fn->getBody()->getSourceRange()));
    c.model.lockedCopies.push_back(copy);
  }
}

}  // namespace crossrt::engine
