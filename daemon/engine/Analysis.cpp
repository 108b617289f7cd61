#include "Analysis.h"

#include "Canonical.h"
#include "Glsl.h"

#include <clang/AST/ParentMapContext.h>
#include <clang/AST/RecursiveASTVisitor.h>
#include <clang/Basic/SourceManager.h>
#include <clang/Lex/Lexer.h>
#include <clang/Rewrite/Core/Rewriter.h>
#include <llvm/Support/FileSystem.h>
#include <llvm/Support/Path.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <optional>
#include <regex>
#include <sstream>

using namespace clang;

namespace crossrt::engine {
namespace {

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

// "[[crossrt::size("n")]] const float* in" -> "const float* in"
std::string StripAttributes(std::string s) {
  static const std::regex cxx11(R"(\[\[[^\]]*\]\]\s*)");
  static const std::regex gnu(R"(__attribute__\s*\(\((?:[^()]|\((?:[^()]|\([^()]*\))*\))*\)\)\s*)");
  s = std::regex_replace(s, cxx11, "");
  s = std::regex_replace(s, gnu, "");
  while (!s.empty() && isspace((unsigned char)s.back())) s.pop_back();
  return s;
}

std::string ParamDecl(const ASTContext& ctx, const ParmVarDecl* p, unsigned index) {
  std::string name = p->getNameAsString();
  if (name.empty()) return p->getType().getAsString(ctx.getPrintingPolicy()) + " a_unnamed" + std::to_string(index);
  SourceRange range(p->getBeginLoc(), p->getLocation());
  return StripAttributes(Text(ctx, range));
}

// A parameter as the declaration `p` writes its type (valid where the class is declared), named
// as the definition `named` names it (its body uses that name).
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

// The member a written lvalue belongs to: this->m_v[i].x -> m_v.
const FieldDecl* RootField(const Expr* e) {
  while (true) {
    e = e->IgnoreParenImpCasts();
    if (auto* f = ThisField(e)) return f;
    if (auto* as = dyn_cast<ArraySubscriptExpr>(e)) { e = as->getBase(); continue; }
    if (auto* op = dyn_cast<CXXOperatorCallExpr>(e); op && op->getOperator() == OO_Subscript) { e = op->getArg(0); continue; }
    if (auto* me = dyn_cast<MemberExpr>(e)) { e = me->getBase(); continue; }
    return nullptr;
  }
}

bool IsKernelName(StringRef n) {
  return n.starts_with("kernel_") || n.starts_with("kernel1D_") || n.starts_with("kernel2D_") || n.starts_with("kernel3D_");
}
unsigned IpvDims(StringRef n) {
  if (n.starts_with("kernel1D_")) return 1;
  if (n.starts_with("kernel2D_")) return 2;
  if (n.starts_with("kernel3D_")) return 3;
  return 0;
}
bool IsThreadIdName(StringRef n) { return n == "tid" || n == "tidX" || n == "tidY" || n == "tidZ"; }
unsigned ThreadAxis(StringRef n) { return n == "tidY" ? 1 : n == "tidZ" ? 2 : 0; }

// The variable an expression names (through parentheses, implicit casts and copies), or null.
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

// The variable at the root of a written expression: v in v, v.f, v[i], v.f[i].g; else null.
const VarDecl* WrittenVar(const clang::Expr* e) {
  for (;;) {
    e = e->IgnoreParenImpCasts();
    if (auto* me = dyn_cast<MemberExpr>(e)) e = me->getBase();
    else if (auto* sub = dyn_cast<ArraySubscriptExpr>(e)) e = sub->getBase();
    else if (auto* op = dyn_cast<CXXOperatorCallExpr>(e); op && op->getOperator() == OO_Subscript) e = op->getArg(0);
    else return NamedVar(e);
  }
}

// Calls Derived::Written(target, loc) for every assignment, increment and overloaded assignment operator.
template <class Derived>
struct WriteVisitor : RecursiveASTVisitor<Derived> {
  bool VisitBinaryOperator(BinaryOperator* bo) {
    if (bo->isAssignmentOp()) Self().Written(bo->getLHS(), bo->getExprLoc());
    return true;
  }
  bool VisitUnaryOperator(UnaryOperator* uo) {
    if (uo->isIncrementDecrementOp()) Self().Written(uo->getSubExpr(), uo->getExprLoc());
    return true;
  }
  bool VisitCXXOperatorCallExpr(CXXOperatorCallExpr* op) {
    if (op->isAssignmentOp() || op->getOperator() == OO_PlusPlus || op->getOperator() == OO_MinusMinus) Self().Written(op->getArg(0), op->getExprLoc());
    return true;
  }
  Derived& Self() { return static_cast<Derived&>(*this); }
};


// The data members kernels may use: the bases' first (in declaration order), then the class's own.
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

// The member functions a translation looks at: the class's own, then those of its bases it does not
// hide by name (a control function or kernel declared in a base, kernel_slicer's inheritance form).
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

// The class or one of its bases: a member function defined there is one of the class's.
bool IsClassOrBase(const CXXRecordDecl* rd, const CXXRecordDecl* cls) {
  return rd && (rd == cls || cls->isDerivedFrom(rd));
}

struct Context {
  ASTContext& ctx;
  const CXXRecordDecl* cls;
  Reporter& rep;
  ClassModel& model;
  const std::map<std::string, std::string>& compositions;  // interface -> implementation
  std::set<std::string> appended;  // member vectors some kernel push_backs to
  // (kernel, parameter) pairs a control function's thread loop passes a local's address to.
  std::set<std::pair<std::string, std::string>> threadState;
  std::string Text(SourceRange r) const { return engine::Text(ctx, r); }
};

// `m_v.push_back(x)` on a std::vector member of the class: the member, else null.
const FieldDecl* AppendTarget(const CXXMemberCallExpr* call) {
  auto* md = call->getMethodDecl();
  if (!md || md->getName() != "push_back") return nullptr;
  auto* f = ThisField(call->getImplicitObjectArgument());
  return f && IsStdVector(f->getType()) ? f : nullptr;
}

// The variable `v` of an argument written `&v`, else null.
const VarDecl* AddressedVar(const Expr* arg) {
  auto* uo = dyn_cast<UnaryOperator>(arg->IgnoreParenImpCasts());
  auto* dr = uo && uo->getOpcode() == UO_AddrOf ? dyn_cast<DeclRefExpr>(uo->getSubExpr()->IgnoreParens()) : nullptr;
  return dr ? dyn_cast<VarDecl>(dr->getDecl()) : nullptr;
}

// The class's own member function a call `this->f(...)` reaches, defined, else null.
const FunctionDecl* ThisMethodDef(const CXXMemberCallExpr* call, const CXXRecordDecl* cls) {
  auto* md = call->getMethodDecl();
  const FunctionDecl* def = nullptr;
  if (!md || md->isStatic() || !IsClassOrBase(md->getParent(), cls) || !isa<CXXThisExpr>(call->getImplicitObjectArgument()->IgnoreParenImpCasts()))
    return nullptr;
  return md->hasBody(def) ? def : nullptr;
}

// The member vectors that kernels of the class append to, in their bodies or in the member
// functions they call: kernels that loop to their size are dispatched indirectly, and control
// functions may not read them before the kernels are done.
struct AppendFinder : RecursiveASTVisitor<AppendFinder> {
  const CXXRecordDecl* cls;
  std::set<std::string> appended;
  std::set<const FunctionDecl*> visited;
  explicit AppendFinder(const CXXRecordDecl* c) : cls(c) {}
  bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
    if (auto* f = AppendTarget(call)) appended.insert(f->getNameAsString());
    auto* md = call->getMethodDecl();
    if (auto* def = ThisMethodDef(call, cls); def && !IsKernelName(md->getName()) && visited.insert(def).second) TraverseStmt(def->getBody());
    return true;
  }
};

// Whether `fn` appends to a member vector, itself or through the class's member functions it calls.
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

// ---- members ---------------------------------------------------------------

// A single member of the class-data block: the C++ mirror declares it with alignas(std430
// alignment), so a lone float3 matches; float3x3, bool and arrays of float3 do not.
bool FitsClassData(ASTContext& ctx, QualType t) {
  t = t.getCanonicalType();
  if (IsLiteMathType(t)) return !IsLiteMathType(t, "float3x3");
  if (t->isBuiltinType() || t->isEnumeralType()) return Std430Layout(ctx, t, false).has_value();
  return LayoutMatchesCpp(ctx, t, false);
}

// A destructor Clang has not declared yet (an implicit one) is virtual when a base's is.
bool HasVirtualDestructor(const CXXRecordDecl* rd) {
  if (auto* dtor = rd->getDestructor()) return dtor->isVirtual();
  for (auto& base : rd->bases())
    if (auto* b = base.getType()->getAsCXXRecordDecl(); b && b->hasDefinition() && HasVirtualDestructor(b->getDefinition())) return true;
  return false;
}

void AnalyzeMembers(Context& c) {
  GlslPrinter structs(c.ctx, c.cls, c.rep);
  for (auto* f : ClassFields(c.cls)) {
    Member m;
    m.name = f->getNameAsString();
    m.hostExpr = m.name;
    QualType elem;
    if (IsTextureArray(f->getType(), &elem)) {
      auto format = ImageFormatOf(elem);
      if (!format || format->texel == "uint") continue;  // reported if a kernel uses it
      m.kind = MemberKind::TextureArray;
      m.glslType = format->texel;
      m.vkFormat = format->vkFormat;
      m.elemCppType = CppTypeName(c.ctx, elem);
      m.cppType = CppTypeName(c.ctx, f->getType());
    } else if (IsImage2D(f->getType(), &elem)) {
      auto format = ImageFormatOf(elem);
      if (!format) continue;  // reported if a kernel uses it
      m.kind = MemberKind::Image;
      m.glslType = format->texel;
      m.imageFormat = format->glslFormat;
      m.vkFormat = format->vkFormat;
      m.imagePrefix = format->prefix;
      m.elemCppType = CppTypeName(c.ctx, elem);
      m.cppType = CppTypeName(c.ctx, f->getType());
    } else if (IsImageSampler(f->getType())) {
      m.kind = MemberKind::Sampler;
      m.cppType = CppTypeName(c.ctx, f->getType());
    } else if (IsStdVector(f->getType(), &elem)) {
      auto g = GlslTypeOf(elem);
      if (!g) continue;  // reported if a kernel uses it
      m.kind = MemberKind::Vector;
      m.glslType = *g;
      m.elemCppType = CppTypeName(c.ctx, elem);
      m.cppType = CppTypeName(c.ctx, f->getType());
      m.scalarLayout = !LayoutMatchesCpp(c.ctx, elem, false);
      if (f->getAccess() != AS_private && (!m.scalarLayout || LayoutMatchesCpp(c.ctx, elem, true))) structs.Type(elem, f->getLocation());
    } else {
      auto g = GlslTypeOf(f->getType());
      if (!g) continue;
      m.kind = MemberKind::Plain;
      m.glslType = *g;
      QualType base = f->getType();
      while (auto* arr = dyn_cast<ConstantArrayType>(base.getCanonicalType().getTypePtr())) base = arr->getElementType();
      m.cppType = CppTypeName(c.ctx, base);
      m.inClassData = f->getAccess() != AS_private && FitsClassData(c.ctx, f->getType());
      if (auto layout = Std430Layout(c.ctx, f->getType(), false)) m.std430Align = unsigned(layout->align);
      if (m.inClassData) structs.Type(f->getType(), f->getLocation());
    }
    c.model.members.push_back(m);
  }
  c.model.glslClassStructs = structs.PreludeTypes();
  for (auto* ctor : c.cls->ctors()) {
    if (ctor->isImplicit() || ctor->isCopyOrMoveConstructor() || ctor->isDeleted() || ctor->getAccess() == AS_private) continue;
    Constructor k;
    for (unsigned i = 0; i < ctor->getNumParams(); ++i) {
      k.paramsDecl += (i ? ", " : "") + ParamDecl(c.ctx, ctor->getParamDecl(i), i);
      std::string n = ctor->getParamDecl(i)->getNameAsString();
      k.argsForward += (i ? ", " : "") + (n.empty() ? "a_unnamed" + std::to_string(i) : n);
    }
    c.model.constructors.push_back(k);
  }
  if (c.model.constructors.empty()) c.model.constructors.push_back({});
  c.model.virtualDestructor = HasVirtualDestructor(c.cls);
  for (auto* md : ClassMethods(c.cls)) {
    if (md->getName() == "CommitDeviceData" && md->isVirtual()) c.model.declaresCommitDeviceData = true;
    if (md->getName() == "GetExecutionTime" && md->isVirtual()) c.model.declaresGetExecutionTime = true;
  }
}

// Struct names already declared by the class-wide prelude ("struct Foo {  // ...").
std::set<std::string> ClassStructNames(const ClassModel& model) {
  std::set<std::string> names;
  static const std::regex decl(R"(struct (\w+) \{)");
  for (std::sregex_iterator it(model.glslClassStructs.begin(), model.glslClassStructs.end(), decl), end; it != end; ++it)
    names.insert((*it)[1]);
  return names;
}


// ---- kernels ---------------------------------------------------------------

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

// Collects the reductions (m += x, m = min(m, x), ...) and member writes of a thread body.
struct WriteScanner : RecursiveASTVisitor<WriteScanner> {
  Context& c;
  std::map<const FieldDecl*, ReduceOp> reductions;
  std::set<const MemberExpr*> reductionUses;  // member references that belong to a reduction statement
  std::set<const FieldDecl*> vectorWrites;
  std::set<const FieldDecl*> atomicMembers;  // plain data members written by crossrt::Atomic*
  const FunctionDecl* helper = nullptr;  // scanning a helper's body: reductions are not allowed there
  // Scanning statements one thread runs (before or after a kernel's loop nest): members are written
  // as on the CPU, no race and no reduction.
  bool singleThread = false;
  std::set<const FieldDecl*> memberWrites;  // plain members written that way
  explicit WriteScanner(Context& ctx) : c(ctx) {}

  static const MemberExpr* AsThisMember(const Expr* e) {
    auto* me = dyn_cast<MemberExpr>(e->IgnoreParenImpCasts());
    return me && isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts()) ? me : nullptr;
  }
  void Write(const Expr* lhs, SourceLocation loc, std::optional<ReduceOp> op, const std::vector<const MemberExpr*>& uses) {
    const FieldDecl* root = RootField(lhs);
    if (!root) return;
    if (IsStdVector(root->getType())) { vectorWrites.insert(root); return; }
    if (IsImage2D(root->getType())) {
      // m_img[p] = v and m_img.at(x, y) = v print as imageStore; a part of a texel cannot be stored.
      auto* op = dyn_cast<CXXOperatorCallExpr>(lhs->IgnoreParenImpCasts());
      if (!(op && op->getOperator() == OO_Subscript && ThisField(op->getArg(0)) == root))
        c.rep.GpuError(loc, "kernel writes part of a texel of Image2D member '" + root->getNameAsString() + "'",
                    "GPU images store whole texels: read the texel into a variable, change it, and write it back with " +
                    root->getNameAsString() + "[p] = value");
      return;
    }
    auto* direct = AsThisMember(lhs);
    if (singleThread) {
      memberWrites.insert(root);
      return;
    }
    if (helper) {
      c.rep.Error(loc, "helper function '" + helper->getNameAsString() + "' writes class member '" + root->getNameAsString() + "' (called from every thread: a data race)",
                  "accumulate in the kernel's loop body (m += x, min, max), or return the value from the helper");
      return;
    }
    if (op && direct) {
      auto [it, fresh] = reductions.emplace(root, *op);
      if (!fresh && it->second != *op)
        c.rep.Error(loc, "member '" + root->getNameAsString() + "' is reduced with two different operations in one kernel",
                    "use one of +=, -=, min or max per member");
      for (auto* u : uses) reductionUses.insert(u);
      return;
    }
    c.rep.Error(loc, "kernel writes class member '" + root->getNameAsString() + "' from every thread (a data race)",
                "accumulate with 'm += x', 'm = std::min(m, x)' or 'm = std::max(m, x)' (a reduction), or write to an element of a std::vector member");
  }
  std::optional<ReduceOp> MinMax(const Expr* lhs, const Expr* rhs, std::vector<const MemberExpr*>& uses) {
    auto* call = dyn_cast<CallExpr>(rhs->IgnoreImplicit());
    if (!call || !call->getDirectCallee() || call->getNumArgs() != 2) return std::nullopt;
    std::string n = call->getDirectCallee()->getNameAsString();
    bool isMin = n == "min" || n == "fmin" || n == "fminf", isMax = n == "max" || n == "fmax" || n == "fmaxf";
    if (!isMin && !isMax) return std::nullopt;
    auto* target = ThisField(lhs);
    for (auto* arg : call->arguments())
      if (auto* me = AsThisMember(arg); me && target && me->getMemberDecl() == target) {
        uses.push_back(me);
        return isMin ? ReduceOp::Min : ReduceOp::Max;
      }
    return std::nullopt;
  }
  // `m = constant;` of a scalar member from the threads (kernel_slicer's flags: m_found = 1): every
  // thread that stores, stores the same value, so the result is that of the CPU. Stored
  // atomically on the CPU; the values of each member must agree, and no thread may read it.
  std::map<const FieldDecl*, std::set<std::string>> constantStores;
  std::vector<const BinaryOperator*> constantStoreExprs;
  std::set<const MemberExpr*> constantStoreUses;
  bool ConstantStore(BinaryOperator* bo) {
    auto* me = AsThisMember(bo->getLHS());
    auto* f = me ? dyn_cast<FieldDecl>(me->getMemberDecl()) : nullptr;
    Expr::EvalResult r;
    if (!f || bo->getOpcode() != BO_Assign || singleThread || helper || !f->getType()->isScalarType() || f->getType()->isPointerType() ||
        !bo->getRHS()->EvaluateAsRValue(r, c.ctx))
      return false;
    constantStores[f].insert(r.Val.getAsString(c.ctx, bo->getRHS()->getType()));
    constantStoreExprs.push_back(bo);
    constantStoreUses.insert(me);
    return true;
  }
  bool VisitBinaryOperator(BinaryOperator* bo) {
    if (!bo->isAssignmentOp() || ConstantStore(bo)) return true;
    std::vector<const MemberExpr*> uses;
    if (auto* me = AsThisMember(bo->getLHS())) uses.push_back(me);
    std::optional<ReduceOp> op;
    if (bo->getOpcode() == BO_AddAssign) op = ReduceOp::Add;
    else if (bo->getOpcode() == BO_SubAssign) op = ReduceOp::Sub;
    else if (bo->getOpcode() == BO_Assign) op = MinMax(bo->getLHS(), bo->getRHS(), uses);
    Write(bo->getLHS(), bo->getExprLoc(), op, uses);
    return true;
  }
  bool VisitCXXOperatorCallExpr(CXXOperatorCallExpr* op) {
    auto k = op->getOperator();
    if (k != OO_PlusEqual && k != OO_MinusEqual && k != OO_Equal && k != OO_StarEqual && k != OO_SlashEqual &&
        k != OO_PlusPlus && k != OO_MinusMinus)
      return true;
    std::vector<const MemberExpr*> uses;
    if (auto* me = AsThisMember(op->getArg(0))) uses.push_back(me);
    std::optional<ReduceOp> r;
    if (k == OO_PlusEqual) r = ReduceOp::Add;
    else if (k == OO_MinusEqual) r = ReduceOp::Sub;
    else if (k == OO_Equal) r = MinMax(op->getArg(0), op->getArg(1), uses);
    Write(op->getArg(0), op->getExprLoc(), r, uses);
    return true;
  }
  bool VisitUnaryOperator(UnaryOperator* uo) {
    if (!uo->isIncrementDecrementOp()) return true;
    // m++ and m-- on a member are reductions, as m += 1 and m -= 1 are.
    std::vector<const MemberExpr*> uses;
    std::optional<ReduceOp> op;
    if (auto* me = AsThisMember(uo->getSubExpr()); me && uo->getSubExpr()->getType()->isArithmeticType()) {
      uses.push_back(me);
      op = uo->isIncrementOp() ? ReduceOp::Add : ReduceOp::Sub;
    }
    Write(uo->getSubExpr(), uo->getExprLoc(), op, uses);
    return true;
  }
  // push_back to a member vector: an append through an atomic counter on the GPU; on the CPU a
  // lock, in the kernel's loop and in copies of the helpers on the way (LockedCopy).
  std::map<const FieldDecl*, SourceLocation> appends;
  bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
    if (auto* f = AppendTarget(call)) appends.emplace(f, call->getExprLoc());
    return true;
  }
  // A member passed to a non-const reference parameter may be written by the callee (GLSL inout).
  bool VisitCallExpr(CallExpr* call) {
    auto* fd = call->getDirectCallee();
    // An atomic's target may be written by every thread, in a helper too: no race, no reduction.
    if (IsCrossrtAtomic(fd) && call->getNumArgs() > 0) {
      if (auto* root = RootField(call->getArg(0))) (IsStdVector(root->getType()) ? vectorWrites : atomicMembers).insert(root);
      return true;
    }
    if (!fd || IsSystemDecl(fd) || isa<CXXOperatorCallExpr>(call)) return true;
    for (unsigned i = 0; i < call->getNumArgs() && i < fd->getNumParams(); ++i) {
      QualType t = fd->getParamDecl(i)->getType();
      const Expr* arg = call->getArg(i);
      if (t->isReferenceType() && !t.getNonReferenceType().isConstQualified())
        Write(arg, arg->getExprLoc(), std::nullopt, {});
      // A pointer to non-const: the callee may write what it points at (&m_v[i], m_v.data() + k).
      if (!t->isPointerType() || t->getPointeeType().isConstQualified()) continue;
      const Expr* target = arg->IgnoreParenImpCasts();
      while (auto* bo = dyn_cast<BinaryOperator>(target)) target = (bo->getLHS()->getType()->isPointerType() ? bo->getLHS() : bo->getRHS())->IgnoreParenImpCasts();
      if (auto* uo = dyn_cast<UnaryOperator>(target); uo && uo->getOpcode() == UO_AddrOf) Write(uo->getSubExpr(), arg->getExprLoc(), std::nullopt, {});
      if (auto* mc = dyn_cast<CXXMemberCallExpr>(target); mc && mc->getMethodDecl() && mc->getMethodDecl()->getName() == "data")
        if (auto* f = ThisField(mc->getImplicitObjectArgument()); f && IsStdVector(f->getType())) vectorWrites.insert(f);
    }
    return true;
  }
};

// Every other read of a reduction target inside the kernel would see a partial sum.
struct ReductionReadScanner : RecursiveASTVisitor<ReductionReadScanner> {
  Context& c;
  const WriteScanner& w;
  ReductionReadScanner(Context& ctx, const WriteScanner& ws) : c(ctx), w(ws) {}
  bool VisitMemberExpr(MemberExpr* me) {
    auto* f = dyn_cast<FieldDecl>(me->getMemberDecl());
    if (f && w.reductions.count(f) && !w.reductionUses.count(me) && isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts()))
      c.rep.Error(me->getExprLoc(), "kernel reads '" + f->getNameAsString() + "', which it also reduces",
                  "the value is only known after all threads finish: read it in the control function after the kernel");
    return true;
  }
};

std::string Identity(ReduceOp op, const std::string& glslType) {
  std::string scalar = glslType.find("vec") == std::string::npos ? glslType
                       : glslType[0] == 'i' ? "int" : glslType[0] == 'u' ? "uint" : "float";
  std::string v;
  if (op == ReduceOp::Add || op == ReduceOp::Sub) v = scalar == "float" ? "0.0" : scalar == "uint" ? "0u" : "0";
  // +-infinity, so that infinite inputs reduce exactly as on the CPU
  else if (op == ReduceOp::Min) v = scalar == "float" ? "uintBitsToFloat(0x7F800000u)" : scalar == "uint" ? "0xFFFFFFFFu" : "0x7FFFFFFF";
  else v = scalar == "float" ? "uintBitsToFloat(0xFF800000u)" : scalar == "uint" ? "0u" : "(-2147483647 - 1)";
  return glslType == scalar ? v : glslType + "(" + v + ")";
}

struct LoopHeader {
  const VarDecl* var = nullptr;
  const Expr* start = nullptr;
  const Expr* end = nullptr;
  bool inclusive = false;
};

// Accepts `for (T i = a; i < b; ++i)` (also i++, i += 1, <=). Returns false and reports otherwise.
bool ParseLoop(Context& c, const ForStmt* fs, LoopHeader& h, const std::string& kernel) {
  auto bad = [&](const std::string& what) {
    c.rep.Error(fs->getBeginLoc(), "loop of kernel '" + kernel + "' is not a parallel loop: " + what,
                "write it as 'for (int i = start; i < end; i++)'; each iteration becomes one thread");
    return false;
  };
  auto* ds = dyn_cast_or_null<DeclStmt>(fs->getInit());
  if (!ds || !ds->isSingleDecl()) return bad("it must declare one loop variable");
  h.var = dyn_cast<VarDecl>(ds->getSingleDecl());
  if (!h.var || !h.var->getInit() || !h.var->getType()->isIntegerType()) return bad("the loop variable must be an initialised integer");
  h.start = h.var->getInit();
  auto* cond = dyn_cast_or_null<BinaryOperator>(fs->getCond() ? fs->getCond()->IgnoreImplicit() : nullptr);
  if (!cond || (cond->getOpcode() != BO_LT && cond->getOpcode() != BO_LE)) return bad("the condition must be 'i < end' or 'i <= end'");
  auto* lhs = dyn_cast<DeclRefExpr>(cond->getLHS()->IgnoreParenImpCasts());
  if (!lhs || lhs->getDecl() != h.var) return bad("the condition must compare the loop variable");
  h.end = cond->getRHS();
  h.inclusive = cond->getOpcode() == BO_LE;
  const Expr* inc = fs->getInc() ? fs->getInc()->IgnoreImplicit() : nullptr;
  bool stepOne = false;
  if (auto* uo = dyn_cast_or_null<UnaryOperator>(inc)) stepOne = uo->isIncrementOp();
  if (auto* ca = dyn_cast_or_null<CompoundAssignOperator>(inc)) {
    Expr::EvalResult r;
    stepOne = ca->getOpcode() == BO_AddAssign && ca->getRHS()->EvaluateAsInt(r, c.ctx) && r.Val.getInt() == 1;
  }
  if (!stepOne) return bad("the step must be ++i, i++ or i += 1");
  return true;
}

// Casts the host-side C++ count to the loop variable's range: (end) - (start) [+ 1].
std::string CountExpr(Context& c, const LoopHeader& h) {
  std::string end = c.Text(h.end->getSourceRange()), start = c.Text(h.start->getSourceRange());
  Expr::EvalResult r;
  bool zeroStart = h.start->EvaluateAsInt(r, c.ctx) && r.Val.getInt() == 0;
  std::string count = zeroStart ? "(" + end + ")" : "(" + end + ") - (" + start + ")";
  return h.inclusive ? count + " + 1" : count;
}

// A kernel's Image2D reference parameter (by value it is an error the kernel's analysis reports).
bool IsImageParam(const ParmVarDecl* p) {
  return p->getType()->isReferenceType() && IsImage2D(p->getType().getNonReferenceType().getUnqualifiedType());
}

void CheckKernelParams(Context& c, const CXXMethodDecl* md, const FunctionDecl* def, Kernel& k) {
  for (unsigned i = 0; i < md->getNumParams(); ++i) {
    auto* p = md->getParamDecl(i);
    KernelParam kp;
    kp.name = def->getParamDecl(i)->getNameAsString();  // the name the body uses
    if (kp.name.empty()) {
      c.rep.Error(p->getLocation(), "kernel '" + k.name + "' has a parameter without a name", "name it, or remove it");
      continue;
    }
    kp.glslName = GlslPrinter::SafeName(kp.name);
    QualType t = p->getType();
    kp.isThreadId = k.rtv && IsThreadIdName(kp.name);
    QualType texel;
    if (IsImage2D(t.getNonReferenceType().getUnqualifiedType(), &texel)) {
      auto format = ImageFormatOf(texel);
      if (!t->isReferenceType()) {
        c.rep.GpuError(p->getLocation(), "kernel parameter '" + kp.name + "' takes an Image2D by value",
                    "take it by reference: 'const Image2D<T>& " + kp.name + "' to read it, 'Image2D<T>& " + kp.name + "' to write it");
        continue;
      }
      if (!format) {
        c.rep.GpuError(p->getLocation(), "kernel parameter '" + kp.name + "' is an Image2D of '" + texel.getAsString(c.ctx.getPrintingPolicy()) + "', which GPU images cannot hold",
                    "use Image2D<float4>, Image2D<float> or Image2D<uint32_t>");
        continue;
      }
      kp.isImage = true;
      kp.isConstPointee = t.getNonReferenceType().isConstQualified();
      kp.glslType = format->texel;
      kp.imageFormat = format->glslFormat;
      kp.imagePrefix = format->prefix;
      k.params.push_back(kp);
      continue;
    }
    if (t->isPointerType()) {
      QualType pointee = t->getPointeeType();
      kp.isPointer = true;
      kp.threadState = k.rtv && c.threadState.count({k.name, kp.name});
      kp.isConstPointee = pointee.isConstQualified();
      auto g = GlslTypeOf(pointee);
      if (pointee->isRealFloatingType() && !pointee->isSpecificBuiltinType(BuiltinType::Float)) {
        c.rep.GpuError(p->getLocation(), DoubleRefusal(pointee.getUnqualifiedType().getAsString(c.ctx.getPrintingPolicy())), DoubleRefusalHint());
        continue;
      }
      if (!g || pointee->isPointerType()) {
        c.rep.GpuError(p->getLocation(), "kernel parameter '" + kp.name + "' points to '" + pointee.getAsString(c.ctx.getPrintingPolicy()) + "', which has no GPU equivalent",
                    "pass arrays of int, uint, float, LiteMath vectors or plain structs of those");
        continue;
      }
      kp.glslType = *g;
      if (!LayoutMatchesCpp(c.ctx, pointee, false)) {
        if (LayoutMatchesCpp(c.ctx, pointee, true)) kp.scalarLayout = true;
        else c.rep.GpuError(p->getLocation(), "the C++ layout of '" + pointee.getAsString(c.ctx.getPrintingPolicy()) + "' cannot be reproduced in a GPU buffer",
                         "reorder the fields so 16-byte types (float4, float3) come first, or pad them to float4");
      }
    } else if (t->isReferenceType() && !t.getNonReferenceType().isConstQualified()) {
      c.rep.GpuError(p->getLocation(), "kernel parameter '" + kp.name + "' is a non-const reference",
                  "kernels return results through pointer parameters or members");
    } else {
      auto g = GlslTypeOf(t);
      if (t.getNonReferenceType()->isRealFloatingType() && !t.getNonReferenceType()->isSpecificBuiltinType(BuiltinType::Float)) {
        c.rep.GpuError(p->getLocation(), DoubleRefusal(t.getNonReferenceType().getUnqualifiedType().getAsString(c.ctx.getPrintingPolicy())), DoubleRefusalHint());
        continue;
      }
      if (!g) {
        c.rep.GpuError(p->getLocation(), "kernel parameter '" + kp.name + "' of type '" + t.getAsString(c.ctx.getPrintingPolicy()) + "' has no GPU equivalent",
                    "use int, uint, float, LiteMath types, plain structs, or a pointer with a size");
        continue;
      }
      QualType value = t.getNonReferenceType().getUnqualifiedType();
      // 64-bit integers (size_t, int64_t) are 32-bit in shaders, like loop counters of those types.
      if (value->isIntegerType() && c.ctx.getTypeSize(value) == 64) {
        kp.glslType = *g;
        kp.std430Align = 4;
        kp.valueCppType = value->isUnsignedIntegerType() ? "uint32_t" : "int32_t";
        kp.narrowed = true;
        kp.cppType = ParamDecl(c.ctx, p, i);
        kp.cppType = kp.cppType.substr(0, kp.cppType.size() - p->getName().size());
        while (!kp.cppType.empty() && isspace((unsigned char)kp.cppType.back())) kp.cppType.pop_back();
        if (c.rep.GpuRules())
          c.rep.Note(p->getLocation(), "kernel parameter '" + kp.name + "' of type '" + t.getAsString(c.ctx.getPrintingPolicy()) +
                     "' is 32-bit on the GPU: values above " + std::string(value->isUnsignedIntegerType() ? "4294967295" : "2147483647") + " wrap around");
        k.params.push_back(kp);
        continue;
      }
      auto layout = Std430Layout(c.ctx, value, false);
      if (!layout || !FitsClassData(c.ctx, value)) {
        c.rep.GpuError(p->getLocation(), "kernel parameter '" + kp.name + "' of type '" + t.getAsString(c.ctx.getPrintingPolicy()) + "' cannot be passed to the GPU as it is laid out in C++",
                    "use 32-bit int, uint or float, LiteMath vectors, float4x4, or structs whose fields keep the std430 layout (bool is 1 byte in C++, 4 on the GPU: use int)");
        continue;
      }
      kp.std430Align = unsigned(layout->align);
      kp.glslType = *g;
      kp.valueCppType = CppTypeName(c.ctx, value);
      kp.cppType = ParamDecl(c.ctx, p, i);
      kp.cppType = kp.cppType.substr(0, kp.cppType.size() - p->getName().size());  // type part only
      while (!kp.cppType.empty() && isspace((unsigned char)kp.cppType.back())) kp.cppType.pop_back();
    }
    k.params.push_back(kp);
  }
}

// ---- virtual functions -------------------------------------------------------

// Classes of the translation unit (outside system headers) that implement `interface`: concrete
// and derived from it, in declaration order.
void FindImplementations(const DeclContext* dc, const CXXRecordDecl* interface, std::vector<const CXXRecordDecl*>& out) {
  for (auto* d : dc->decls()) {
    if (auto* ns = dyn_cast<NamespaceDecl>(d); ns && !ns->isStdNamespace() && !IsSystemDecl(ns)) FindImplementations(ns, interface, out);
    auto* rd = dyn_cast<CXXRecordDecl>(d);
    if (!rd || !rd->isThisDeclarationADefinition() || IsSystemDecl(rd) || rd->isAbstract() || rd->isDependentContext()) continue;
    if (rd->isDerivedFrom(interface)) out.push_back(rd);
    FindImplementations(rd, interface, out);  // nested classes
  }
}

// The data of an object, base classes first, as the GPU mirror holds it.
void CollectObjectFields(const CXXRecordDecl* rd, std::vector<const FieldDecl*>& out) {
  for (auto& base : rd->bases())
    if (auto* b = base.getType()->getAsCXXRecordDecl(); b && b->hasDefinition()) CollectObjectFields(b->getDefinition(), out);
  for (auto* f : rd->fields()) out.push_back(f);
}

// Offsets of a struct with these fields, in order, laid out by C++ (natural alignment) or by a GLSL
// layout; nullopt when a field has no GLSL layout.
std::optional<std::vector<uint64_t>> MirrorOffsets(ASTContext& ctx, const std::vector<const FieldDecl*>& fields, int layout /* 0 C++, 1 std430, 2 scalar */) {
  std::vector<uint64_t> offsets;
  uint64_t offset = 0, align = 1;
  for (auto* f : fields) {
    uint64_t a, size;
    if (layout == 0) {
      a = ctx.getTypeAlignInChars(f->getType()).getQuantity();
      size = ctx.getTypeSizeInChars(f->getType()).getQuantity();
    } else {
      auto l = Std430Layout(ctx, f->getType(), layout == 2);
      if (!l) return std::nullopt;
      a = l->align;
      size = l->size;
    }
    offset = (offset + a - 1) / a * a;
    offsets.push_back(offset);
    offset += size;
    align = std::max(align, a);
  }
  offsets.push_back((offset + align - 1) / align * align);  // the array stride
  return offsets;
}

// The implementation of `method` the GPU runs for objects of `impl`: its GLSL name, or "" (reported).
std::string ImplementationMethod(Reporter& rep, GlslPrinter& printer, const CXXRecordDecl* impl, const CXXMethodDecl* method, SourceLocation callLoc) {
  const CXXMethodDecl* overrider = method->getCorrespondingMethodInClass(impl);
  const FunctionDecl* def = nullptr;
  if (!overrider || overrider->isPureVirtual() || !overrider->hasBody(def) || !def) {
    rep.GpuError(callLoc, "the GPU needs the body of " + impl->getNameAsString() + "'s " + method->getNameAsString() +
                " (kernels call it through virtual functions), but this translation unit does not define it",
                "define it in the header that declares " + impl->getNameAsString() + ", or in the class's source file");
    return "";
  }
  return printer.EmitComposedMethod(overrider);
}

// Where the vectors of objects that code calls virtual functions through live: the translated
// class (its own members), or a composed implementation (the code of listing 2 of the paper: a
// traversal calling an intersection function per primitive), whose members the generated class
// reaches through the holder and whose GLSL names carry the holder's prefix.
struct VirtualOwner {
  const CXXRecordDecl* cls;  // the class declaring the vectors
  std::string prefix;        // "" or "m_scene_"
  std::string hostPrefix;    // "" or "crt_m_scene()->"
  std::string holder;        // "" or "m_scene"
};

// The generated class derives from `cls` and names member `f`: a private one is an error.
void RequireReachable(Reporter& rep, const FieldDecl* f, const CXXRecordDecl* cls) {
  if (f->getAccess() == AS_private)
    rep.Error(f->getLocation(), "member '" + f->getNameAsString() + "' is private, but the generated class derives from '" + cls->getNameAsString() + "' and must reach it",
              "declare it protected");
}

// The generated class reaches member `f` of a composed implementation through an `implName`*: a
// member the GPU reads must be public. `how` names the composition, "" or " (IScene=ShapeScene)".
void RequirePublicForComposition(Reporter& rep, const FieldDecl* f, const std::string& implName, const std::string& how) {
  if (f->getAccess() != AS_public)
    rep.GpuError(f->getLocation(), "member '" + f->getNameAsString() + "' of " + implName + " is read on the GPU through composition" + how +
              ", so the generated class must reach it through a " + implName + "*", "declare it public");
}

// The GLSL name of a virtual method's parameter i: the interface's (it may leave it unnamed).
std::string CallArgumentName(const CXXMethodDecl* m, unsigned i) {
  const ParmVarDecl* p = m->getParamDecl(i);
  return p->getName().empty() ? "arg" + std::to_string(i) : GlslPrinter::SafeName(p->getNameAsString());
}

// A non-const reference parameter of a virtual method: its value comes back to the caller.
bool WrittenBack(const CXXMethodDecl* m, unsigned i) {
  QualType pt = m->getParamDecl(i)->getType();
  return pt->isReferenceType() && !pt.getNonReferenceType().isConstQualified();
}

// ", vec3 normal, inout float weight": a dispatcher's parameters after the element's index.
std::string DispatcherParams(GlslPrinter& printer, const CXXMethodDecl* m) {
  std::string out;
  for (unsigned i = 0; i < m->getNumParams(); ++i)
    out += std::string(", ") + (WrittenBack(m, i) ? "inout " : "") +
           printer.Declare(m->getParamDecl(i)->getType(), CallArgumentName(m, i), m->getParamDecl(i)->getLocation());
  return out;
}

// The buffer reference to a vector's tags: per element, its class and where its object is.
std::string TagsReference(const ClassModel& model, const VirtualMember& vm) {
  return "layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer " + vm.member + "_Tags { uvec2 tags[]; };  // per element of " +
         vm.display + ": (class, " + (model.virtualLevel == 1 ? "its slot" : "index among its class's objects") + ")\n";
}

// The GLSL mirror of the data of an implementation's objects (printed by its object-mode printer).
std::string ImplDataStruct(GlslPrinter& printer, const CXXRecordDecl* impl, const VirtualMember& vm, const VirtualImpl& vi) {
  std::ostringstream data;
  data << "struct " << vi.name << "_Data {  // the data members of " << vi.name << "\n";
  std::vector<const FieldDecl*> fields;
  CollectObjectFields(impl, fields);
  for (auto* f : fields) data << "  " << printer.Declare(f->getType(), GlslPrinter::SafeName(f->getNameAsString()), f->getLocation()) << ";\n";
  if (vi.paddingWords > 0)
    data << "  uint crt_padding[" << vi.paddingWords << "];  // every element of a vector of " << vm.interfaceName << " has a slot of " << vm.slotBytes
         << " bytes\n";
  data << "};\n";
  return data.str();
}

// The buffer reference to the objects of one implementation (level 2 and 3).
std::string ObjectsReference(const VirtualMember& vm, const VirtualImpl& vi) {
  return std::string("layout(buffer_reference, ") + (vi.scalarLayout ? "scalar" : "std430") + ", buffer_reference_align = 4) readonly buffer " +
         vm.member + "_" + vi.name + "Objects { " + vi.name + "_Data objects[]; };\n";
}

// Level 3: what a kernel's ray generation shader has instead of the switches.
struct CallableCode {
  std::vector<std::string> structs;    // the vectors' tags, the calls' payloads and the variables passed to executeCallableEXT
  std::vector<std::string> functions;  // per method, a dispatcher that executes the callable shader of the object's class
  unsigned payloads = 0;               // callableDataEXT variables so far: the next one's location
};

// Level 3: `vm`'s implementation `vi` (an object of class `impl`) of `method` as a callable shader,
// named <member>_<class>_<method>, added to the model unless another kernel added it.
void AddCallableShader(ASTContext& ctx, Reporter& rep, ClassModel& model, const VirtualMember& vm, const VirtualImpl& vi,
                       const CXXRecordDecl* impl, const CXXMethodDecl* method, SourceLocation callLoc, const std::string& dataStruct,
                       const std::string& objectsReference, const std::string& payload) {
  const std::string name = vm.member + "_" + vi.name + "_" + method->getNameAsString();
  if (std::any_of(model.callables.begin(), model.callables.end(), [&](const StageShader& c) { return c.name == name; })) return;
  GlslPrinter printer(ctx, impl, rep);
  printer.selfClass = impl;
  printer.composedPrefix = vi.name + "_";
  for (auto& sn : ClassStructNames(model)) printer.predeclaredStructs.insert(sn);
  const std::string function = ImplementationMethod(rep, printer, impl, method, callLoc);
  if (function.empty()) return;
  StageShader c;
  c.name = name;
  c.stage = "rcall";
  c.origin = vi.name + "::" + method->getNameAsString();
  c.description = "what " + vm.display + "[index]->" + method->getNameAsString() + (method->getNumParams() ? "(...)" : "()") +
                  " runs when the object is\n// a " + vi.name +
                  ", as a callable shader of the ray tracing pipelines of the kernels calling it (virtual functions, level 3)";
  c.scalarLayout = vi.scalarLayout;
  for (auto& x : printer.Constants()) c.constants += x;
  for (auto& x : printer.Structs()) c.structs += x + "\n";
  c.structs += dataStruct + "\n" + objectsReference + "\n" + payload + "layout(location = 0) callableDataInEXT " + vm.member + "_" + method->getNameAsString() +
               "_Call call;\n";
  for (auto& x : printer.Functions()) c.functions += x + "\n";
  std::string args = "self";
  for (unsigned i = 0; i < method->getNumParams(); ++i) args += ", call." + CallArgumentName(method, i);
  const std::string invoke = function + "(" + args + ")";
  c.mainBody = "  const " + vi.name + "_Data self = " + vm.member + "_" + vi.name + "Objects(call.crt_objects).objects[call.crt_index];\n  " +
               (method->getReturnType()->isVoidType() ? invoke : "call.crt_result = " + invoke) + ";\n";
  model.callables.push_back(c);
}

// Level 3: `m` called through `vm` from a kernel's ray generation shader. Its payload, and a
// dispatcher that fills it and executes the callable shader of the object's class (numbered after
// the kernel's callables so far); each implementation's callable shader joins the model.
void CallableDispatcher(ASTContext& ctx, Reporter& rep, ClassModel& model, Kernel& k, GlslPrinter& kernelPrinter, const VirtualMember& vm,
                        const std::vector<const CXXRecordDecl*>& impls, const CXXMethodDecl* m, SourceLocation callLoc,
                        const std::map<std::string, std::pair<std::string, std::string>>& implData, CallableCode& out) {
  const std::string method = m->getNameAsString(), callName = vm.member + "_" + method, variable = callName + "_call";
  const std::string display = vm.display + "[index]->" + method + (m->getNumParams() ? "(...)" : "()");
  auto ret = kernelPrinter.Type(m->getReturnType(), m->getLocation());
  const std::string retType = ret ? *ret : "void";
  std::ostringstream payload;
  payload << "// " << display << ": its arguments and result, passed to the callable shader of the object's class\n";
  payload << "struct " << callName << "_Call\n{\n  uvec2 crt_objects;  // the objects of its class (a buffer reference)\n"
          << "  uint crt_index;     // the object's index among them\n";
  for (unsigned i = 0; i < m->getNumParams(); ++i) {
    const ParmVarDecl* p = m->getParamDecl(i);
    payload << "  " << kernelPrinter.Declare(p->getType().getNonReferenceType().getUnqualifiedType(), CallArgumentName(m, i), p->getLocation()) << ";\n";
  }
  if (retType != "void") payload << "  " << retType << " crt_result;\n";
  payload << "};\n";
  const size_t location = out.payloads++, first = k.callables.size();
  out.structs.push_back(payload.str() + "layout(location = " + std::to_string(location) + ") callableDataEXT " + callName + "_Call " + variable + ";\n");

  std::string names;
  for (const VirtualImpl& vi : vm.impls) {
    auto impl = std::find_if(impls.begin(), impls.end(), [&](const CXXRecordDecl* r) { return r->getNameAsString() == vi.name; });
    const auto& [dataStruct, objectsReference] = implData.at(vi.name);
    AddCallableShader(ctx, rep, model, vm, vi, *impl, m, callLoc, dataStruct, objectsReference, payload.str());
    k.callables.push_back(vm.member + "_" + vi.name + "_" + method);
    names += (names.empty() ? "" : ", ") + k.callables.back();
  }
  std::ostringstream os;
  os << "// " << display << ": the callable shader of the object's class runs its implementation\n";
  os << retType << " " << callName << "(uint index" << DispatcherParams(kernelPrinter, m) << ")\n{\n";
  os << "  const uvec2 tag = " << vm.member << "_Tags(" << vm.member << "_tags).tags[index];\n";
  os << "  switch (tag.x)  // the objects of its class\n  {\n";
  for (size_t t = 0; t < vm.impls.size(); ++t)
    os << "    case " << t << "u: " << variable << ".crt_objects = " << vm.member << "_" << vm.impls[t].name << "; break;\n";
  os << "  }\n  " << variable << ".crt_index = tag.y;\n";
  for (unsigned i = 0; i < m->getNumParams(); ++i) os << "  " << variable << "." << CallArgumentName(m, i) << " = " << CallArgumentName(m, i) << ";\n";
  os << "  executeCallableEXT(" << first << "u + tag.x, " << location << ");  // " << names << "\n";
  for (unsigned i = 0; i < m->getNumParams(); ++i)
    if (WrittenBack(m, i)) os << "  " << CallArgumentName(m, i) << " = " << variable << "." << CallArgumentName(m, i) << ";\n";
  if (retType != "void") os << "  return " << variable << ".crt_result;\n";
  os << "}\n";
  out.functions.push_back(os.str());
}

// Code calls `m_objects[i]->Method(...)`: for every implementation of the interface, its data as
// a GLSL struct in a buffer of its own (reached by a buffer reference), its methods printed with
// `self`, and per method a dispatcher that switches over the object's class. The structs and
// functions to put ahead of the calling code go to `structs` and `functions`; at level 3, with
// `callable` given, also the callable shaders of the implementations and what the ray generation
// shader calls them with.
void VirtualCallCode(ASTContext& ctx, Reporter& rep, ClassModel& model, Kernel& k, GlslPrinter& kernelPrinter, const VirtualOwner& owner,
                     std::vector<std::string>& structs, std::vector<std::string>& functions, CallableCode* callable = nullptr) {
  // Vectors and methods in source order: the generated code must not depend on where the AST
  // happens to sit in memory (the daemon reparses).
  SourceManager& sm = ctx.getSourceManager();
  auto before = [&](const Decl* a, const Decl* b) { return sm.isBeforeInTranslationUnit(a->getLocation(), b->getLocation()); };
  std::vector<std::pair<const FieldDecl*, std::vector<const CXXMethodDecl*>>> calls;
  for (auto& [field, method] : kernelPrinter.virtualCalls) {
    auto same = std::find_if(calls.begin(), calls.end(), [&, f = field](const auto& c) { return c.first == f; });
    if (same == calls.end()) same = calls.insert(calls.end(), {field, {}});
    same->second.push_back(method);
  }
  std::sort(calls.begin(), calls.end(), [&](const auto& a, const auto& b) { return before(a.first, b.first); });
  for (auto& c : calls) std::sort(c.second.begin(), c.second.end(), before);
  for (auto& [field, methods] : calls) {
    QualType element;
    IsStdVector(field->getType(), &element);
    const CXXRecordDecl* interface = PolymorphicPointee(element);
    const std::string member = owner.prefix + field->getNameAsString();
    if (owner.holder.empty()) RequireReachable(rep, field, owner.cls);
    else RequirePublicForComposition(rep, field, owner.cls->getNameAsString(), "");
    std::vector<const CXXRecordDecl*> impls;
    FindImplementations(ctx.getTranslationUnitDecl(), interface, impls);
    if (impls.empty()) {
      rep.GpuError(field->getLocation(), "kernels call " + interface->getNameAsString() + " through '" + member + "', but no class that implements it is defined here",
                  "define the implementations (classes derived from " + interface->getNameAsString() + ") in a header the class's source includes");
      continue;
    }
    auto known = std::find_if(model.virtuals.begin(), model.virtuals.end(), [&](const VirtualMember& v) { return v.member == member; });
    if (known == model.virtuals.end()) {
      VirtualMember vm;
      vm.member = member;
      vm.hostExpr = owner.hostPrefix + field->getNameAsString();
      vm.display = owner.holder.empty() ? member : owner.holder + "->" + field->getNameAsString();
      vm.interfaceName = interface->getNameAsString();
      for (auto* impl : impls) {
        VirtualImpl vi;
        vi.name = impl->getNameAsString();
        vi.header = FileOf(ctx, impl->getLocation());
        std::vector<const FieldDecl*> fields;
        CollectObjectFields(impl, fields);
        bool ok = true;
        for (auto* f : fields) {
          auto g = GlslTypeOf(f->getType());
          if (!g || f->getType()->isPointerType() || IsStdVector(f->getType()) || f->isBitField()) {
            rep.GpuError(f->getLocation(), "member '" + f->getNameAsString() + "' of " + vi.name + " cannot be copied to the GPU (kernels call " + vm.interfaceName +
                        " through '" + member + "')", "objects called through virtual functions hold plain data: scalars, LiteMath types and structs of them");
            ok = false;
            continue;
          }
          if (f->getAccess() != AS_public) {
            rep.GpuError(f->getLocation(), "member '" + f->getNameAsString() + "' of " + vi.name + " is copied to the GPU (kernels call " + vm.interfaceName +
                        " through '" + member + "'), but the generated class cannot read it", "declare it public");
            ok = false;
            continue;
          }
          QualType base = f->getType();
          while (auto* arr = dyn_cast<ConstantArrayType>(base.getCanonicalType().getTypePtr())) base = arr->getElementType();
          vi.fields.push_back({f->getNameAsString(), CppTypeName(ctx, base.getCanonicalType()), *g, 4, "", ""});
        }
        if (!ok) continue;
        auto cpp = MirrorOffsets(ctx, fields, 0), std430 = MirrorOffsets(ctx, fields, 1), scalar = MirrorOffsets(ctx, fields, 2);
        vi.size = unsigned(cpp->back());
        if (std430 && *std430 == *cpp) vi.scalarLayout = false;
        else if (scalar && *scalar == *cpp) vi.scalarLayout = true;
        else {
          rep.GpuError(impl->getLocation(), "the data of " + vi.name + " cannot be laid out on the GPU as C++ lays it out",
                      "use 32-bit scalars and LiteMath vectors; put 16-byte types (float4) first");
          continue;
        }
        vm.impls.push_back(vi);
      }
      if (model.virtualLevel == 1) {  // one slot size for all: the largest class's data, in 16-byte steps
        for (auto& vi : vm.impls) vm.slotBytes = std::max(vm.slotBytes, (vi.size + 15) / 16 * 16);
        for (auto& vi : vm.impls) vi.paddingWords = (vm.slotBytes - vi.size) / 4;
        // The GPU has one <Impl>_Data per class: vectors of two interfaces that share a class
        // must give it the same slot.
        for (auto& other : model.virtuals)
          for (auto& theirs : other.impls)
            for (auto& vi : vm.impls)
              if (theirs.name == vi.name && theirs.paddingWords != vi.paddingWords)
                rep.GpuError(field->getLocation(), "at virtual-function level 1, " + vi.name + " takes a " + std::to_string(vm.slotBytes) + "-byte slot in '" + member +
                          "' but a " + std::to_string(other.slotBytes) + "-byte slot in '" + other.member + "'",
                          "use level 2 (a buffer per class), where a class's objects need no slot");
      }
      model.virtuals.push_back(vm);
      known = model.virtuals.end() - 1;
    }
    const VirtualMember& vm = *known;
    k.bufferReferences = true;
    // Data structs and buffer references, then each implementation's methods.
    const std::string tags = TagsReference(model, vm);
    structs.push_back(tags);
    if (callable) callable->structs.push_back(tags);
    std::map<std::string, std::string> implFunction;  // (impl, method) -> GLSL name
    std::map<std::string, std::pair<std::string, std::string>> implData;  // impl -> (data struct, buffer reference to its objects)
    for (auto* impl : impls) {
      auto vi = std::find_if(vm.impls.begin(), vm.impls.end(), [&](const VirtualImpl& x) { return x.name == impl->getNameAsString(); });
      if (vi == vm.impls.end()) continue;
      GlslPrinter printer(ctx, impl, rep);
      printer.selfClass = impl;
      printer.composedPrefix = vi->name + "_";
      for (auto& sn : ClassStructNames(model)) printer.predeclaredStructs.insert(sn);
      const std::string data = ImplDataStruct(printer, impl, vm, *vi);
      for (auto* m : methods) implFunction[vi->name + "::" + m->getNameAsString()] = ImplementationMethod(rep, printer, impl, m, field->getLocation());
      for (auto& x : printer.Structs()) structs.push_back(x);
      const std::string objectsReference = ObjectsReference(vm, *vi);
      structs.push_back(data);
      structs.push_back(objectsReference);
      implData[vi->name] = {data, objectsReference};
      k.scalarReferences |= vi->scalarLayout;
      for (auto& x : printer.Constants())
        if (std::find(k.constantList.begin(), k.constantList.end(), x) == k.constantList.end()) k.constantList.push_back(x);
      for (auto& x : printer.Functions()) functions.push_back(x);
    }
    for (auto* m : methods) {
      std::ostringstream os;
      auto ret = kernelPrinter.Type(m->getReturnType(), m->getLocation());
      const std::string retType = ret ? *ret : "void";
      os << "// " << vm.display << "[index]->" << m->getNameAsString() << (m->getNumParams() ? "(...)" : "()") << ": the object's class picks the implementation\n";
      os << retType << " " << member << "_" << m->getNameAsString() << "(uint index" << DispatcherParams(kernelPrinter, m) << ")\n{\n";
      os << "  const uvec2 tag = " << member << "_Tags(" << member << "_tags).tags[index];\n  switch (tag.x)\n  {\n";
      for (size_t t = 0; t < vm.impls.size(); ++t) {
        const auto& vi = vm.impls[t];
        // Level 1: all elements in one array of equal slots; level 2: each class's objects apart.
        const std::string address = member + (model.virtualLevel == 1 ? std::string("_objects") : "_" + vi.name);
        std::string args = member + "_" + vi.name + "Objects(" + address + ").objects[tag.y]";
        for (unsigned i = 0; i < m->getNumParams(); ++i) args += ", " + CallArgumentName(m, i);
        const std::string call = implFunction[vi.name + "::" + m->getNameAsString()] + "(" + args + ")";
        os << "    case " << t << "u: " << (retType == "void" ? call + "; return;" : "return " + call + ";") << "\n";
      }
      os << "  }\n";
      if (retType != "void") os << "  " << retType << " none;  // not reached: every element holds one of these classes\n  return none;\n";
      os << "}\n";
      functions.push_back(os.str());
      if (callable) CallableDispatcher(ctx, rep, model, k, kernelPrinter, vm, impls, m, field->getLocation(), implData, *callable);
    }
  }
}

// The size of a vector of objects is in the class data next to the vector's tags, which exist for
// vectors the kernel calls through.
void CheckObjectSizeReads(Reporter& rep, const GlslPrinter& printer) {
  for (auto& [field, loc] : printer.objectSizeReads)
    if (std::none_of(printer.virtualCalls.begin(), printer.virtualCalls.end(), [&](const auto& call) { return call.first == field; }))
      rep.GpuError(loc, "the kernel reads the size of '" + field->getNameAsString() + "', a vector of objects it calls no virtual function through",
                "keep the count in a plain member, or read the size where the kernel also calls through the vector");
}

// The kernel's own code calls virtual functions through the class's vectors of objects.
void AnalyzeVirtualCalls(Context& c, Kernel& k, GlslPrinter& kernelPrinter) {
  std::vector<std::string> structs, functions;
  CallableCode callable;
  VirtualCallCode(c.ctx, c.rep, c.model, k, kernelPrinter, VirtualOwner{c.cls, "", "", ""}, structs, functions,
                  c.model.virtualLevel == 3 ? &callable : nullptr);
  if (c.model.virtualLevel == 3) {
    // The ray generation shader needs the tags, not the implementations' code or data.
    k.callableStructList = k.structList;
    for (auto& x : callable.structs) k.callableStructList.push_back(x);
    k.callableFunctionList = callable.functions;
    for (auto& x : k.functionList) k.callableFunctionList.push_back(x);
  }
  // Ahead of the kernel's own code, which calls the dispatchers.
  for (auto& x : structs)
    if (std::find(k.structList.begin(), k.structList.end(), x) == k.structList.end()) k.structList.push_back(x);
  // Free functions both print are the same text: keep the first.
  std::vector<std::string> merged;
  for (auto* list : {&functions, &k.functionList})
    for (auto& x : *list)
      if (std::find(merged.begin(), merged.end(), x) == merged.end()) merged.push_back(x);
  k.functionList = merged;
}

// `v.push_back(x)` -> `crossrt::Locked(v).push_back(x)` for the class's member vectors in `body`.
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

// The member functions a kernel's threads run that append, themselves or through calls: the CPU
// backend gets copies of them whose appends take a lock (see LockedCopy).
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
    const std::string qualified = c.cls->getNameAsString() + "_CPU::" + name + "(" + defParams + ")" + cv;
    copy.definitionHead = nested ? "auto " + qualified + " -> " + ret : ret + " " + qualified;
    Rewriter rw(c.ctx.getSourceManager(), c.ctx.getLangOpts());
    LockAppends(rw, fn->getBody());
    copy.body = CanonicalCode(rw.getRewrittenText(fn->getBody()->getSourceRange()));
    c.model.lockedCopies.push_back(copy);
  }
}

// A statement's source text with its ';' (the AST range of an expression statement ends before it).
std::string StatementText(Context& c, const Stmt* s) {
  auto& sm = c.ctx.getSourceManager();
  SourceLocation end = Lexer::findLocationAfterToken(s->getEndLoc(), tok::semi, sm, c.ctx.getLangOpts(), false);
  if (end.isValid()) return Lexer::getSourceText(CharSourceRange::getCharRange(sm.getExpansionLoc(s->getBeginLoc()), end), sm, c.ctx.getLangOpts()).str();
  return c.Text(s->getSourceRange());
}

// Locals declared before a kernelND_'s loop nest that its threads reduce, as they reduce members:
//   float sum = 0.0f;  for (...) { ... sum += x; best = std::max(best, y); }  m_mean = sum / n;
// Each thread accumulates its part from the identity; after the nest the parts are combined with
// the local's initial value, where the statements after the loop read it. Any other write, or a
// read inside the loop, stays an error (CheckLoopEnds, LocalReductionReads).
struct LocalReductionScanner : RecursiveASTVisitor<LocalReductionScanner> {
  Context& c;
  const std::set<const VarDecl*>& locals;
  std::map<const VarDecl*, ReduceOp> reductions;
  std::set<const Expr*> targets;         // the written expressions of the reduction statements
  std::set<const DeclRefExpr*> uses;     // the references to the locals those statements make
  LocalReductionScanner(Context& ctx, const std::set<const VarDecl*>& l) : c(ctx), locals(l) {}

  const DeclRefExpr* Ref(const Expr* e) const {
    auto* dr = dyn_cast<DeclRefExpr>(e->IgnoreParenImpCasts());
    return dr && isa<VarDecl>(dr->getDecl()) && locals.count(cast<VarDecl>(dr->getDecl())) ? dr : nullptr;
  }
  // x = min(x, v) / max(v, x) (std::, fmin/fmax, LiteMath's): the operation, and the reference to x among the arguments.
  std::optional<ReduceOp> MinMax(const DeclRefExpr* target, const Expr* rhs, const DeclRefExpr*& use) const {
    auto* call = dyn_cast<CallExpr>(rhs->IgnoreImplicit());
    if (!call || !call->getDirectCallee() || call->getNumArgs() != 2) return std::nullopt;
    const std::string n = call->getDirectCallee()->getNameAsString();
    const bool isMin = n == "min" || n == "fmin" || n == "fminf", isMax = n == "max" || n == "fmax" || n == "fmaxf";
    if (!isMin && !isMax) return std::nullopt;
    for (auto* arg : call->arguments())
      if (auto* r = Ref(arg); r && r->getDecl() == target->getDecl()) {
        use = r;
        return isMin ? ReduceOp::Min : ReduceOp::Max;
      }
    return std::nullopt;
  }
  void Found(const Expr* lhs, const DeclRefExpr* target, ReduceOp op, const DeclRefExpr* other, SourceLocation loc) {
    auto* vd = cast<VarDecl>(target->getDecl());
    auto [it, fresh] = reductions.emplace(vd, op);
    if (!fresh && it->second != op)
      c.rep.Error(loc, "local '" + vd->getNameAsString() + "' is reduced with two different operations in one loop nest",
                  "use one of +=, -=, min or max per variable");
    targets.insert(lhs);
    uses.insert(target);
    if (other) uses.insert(other);
  }
  bool VisitBinaryOperator(BinaryOperator* bo) {
    auto* target = bo->isAssignmentOp() ? Ref(bo->getLHS()) : nullptr;
    if (!target || !target->getType()->isArithmeticType()) return true;
    const DeclRefExpr* other = nullptr;
    std::optional<ReduceOp> op;
    if (bo->getOpcode() == BO_AddAssign) op = ReduceOp::Add;
    else if (bo->getOpcode() == BO_SubAssign) op = ReduceOp::Sub;
    else if (bo->getOpcode() == BO_Assign) op = MinMax(target, bo->getRHS(), other);
    if (op) Found(bo->getLHS(), target, *op, other, bo->getExprLoc());
    return true;
  }
  bool VisitCXXOperatorCallExpr(CXXOperatorCallExpr* call) {  // LiteMath vectors: v += x, v = min(v, x)
    auto k = call->getOperator();
    auto* target = (k == OO_PlusEqual || k == OO_MinusEqual || k == OO_Equal) ? Ref(call->getArg(0)) : nullptr;
    if (!target || !GlslTypeOf(target->getType())) return true;
    const DeclRefExpr* other = nullptr;
    std::optional<ReduceOp> op;
    if (k == OO_PlusEqual) op = ReduceOp::Add;
    else if (k == OO_MinusEqual) op = ReduceOp::Sub;
    else op = MinMax(target, call->getArg(1), other);
    if (op) Found(call->getArg(0), target, *op, other, call->getExprLoc());
    return true;
  }
  bool VisitUnaryOperator(UnaryOperator* uo) {  // n++ and n-- count
    auto* target = uo->isIncrementDecrementOp() ? Ref(uo->getSubExpr()) : nullptr;
    if (target && target->getType()->isArithmeticType())
      Found(uo->getSubExpr(), target, uo->isIncrementOp() ? ReduceOp::Add : ReduceOp::Sub, nullptr, uo->getExprLoc());
    return true;
  }
};

// A read of a reduced local inside the loop nest would see one thread's part.
void LocalReductionReads(Context& c, const std::string& kernel, const LocalReductionScanner& scan, const Stmt* threadBody) {
  struct Reads : RecursiveASTVisitor<Reads> {
    Context& c; const std::string& kernel; const LocalReductionScanner& scan;
    Reads(Context& ctx, const std::string& k, const LocalReductionScanner& s) : c(ctx), kernel(k), scan(s) {}
    bool VisitDeclRefExpr(DeclRefExpr* e) {
      auto* vd = dyn_cast<VarDecl>(e->getDecl());
      if (vd && scan.reductions.count(vd) && !scan.uses.count(e))
        c.rep.Error(e->getLocation(), "the loop of kernel '" + kernel + "' reads '" + vd->getNameAsString() + "', which its iterations reduce",
                    "its total is known after the loop: read it in the statements after the loop nest");
      return true;
    }
  } reads(c, kernel, scan);
  reads.TraverseStmt(const_cast<Stmt*>(threadBody));
}

// The statements before and after a kernelND_'s loop nest run on one thread, around the threads of
// the nest: before them (the GPU's <kernel>_Start) and after them (<kernel>_Finish). Every thread
// evaluates the declarations before the nest for itself, so the statements before it may not change
// those locals afterwards, and neither may the threads (a race on the CPU too). A 'return' before
// the nest would skip it on the CPU but not on the GPU.
bool CheckLoopEnds(Context& c, const std::string& kernel, const std::vector<const Stmt*>& before,
                   const std::vector<const Stmt*>& after, const Stmt* threadBody, const std::set<const Expr*>& reductionTargets) {
  std::set<const VarDecl*> locals;
  for (auto* s : before)
    if (auto* ds = dyn_cast<DeclStmt>(s))
      for (auto* d : ds->decls())
        if (auto* vd = dyn_cast<VarDecl>(d)) locals.insert(vd);
  struct LocalWrites : WriteVisitor<LocalWrites> {
    const std::set<const VarDecl*>& locals;
    std::vector<std::pair<const VarDecl*, SourceLocation>> found;
    const std::set<const Expr*>* skip = nullptr;  // the targets of reductions
    explicit LocalWrites(const std::set<const VarDecl*>& l) : locals(l) {}
    void Written(const Expr* target, SourceLocation loc) {
      if (skip && skip->count(target)) return;
      if (auto* vd = WrittenVar(target); vd && locals.count(vd)) found.push_back({vd, loc});
    }
    bool VisitUnaryOperator(UnaryOperator* uo) {
      if (uo->getOpcode() == UO_AddrOf) Written(uo->getSubExpr(), uo->getExprLoc());
      return WriteVisitor<LocalWrites>::VisitUnaryOperator(uo);
    }
  };
  bool ok = true;
  for (auto* s : before) {
    if (isa<DeclStmt>(s)) continue;
    LocalWrites w(locals);
    w.TraverseStmt(const_cast<Stmt*>(s));
    for (auto& [vd, loc] : w.found) {
      c.rep.Error(loc, "a statement before the loop nest of kernel '" + kernel + "' changes '" + vd->getNameAsString() +
                  "', which every thread of the nest computes from its declaration",
                  "give '" + vd->getNameAsString() + "' its final value where it is declared");
      ok = false;
    }
  }
  LocalWrites inLoop(locals);
  inLoop.skip = &reductionTargets;
  inLoop.TraverseStmt(const_cast<Stmt*>(threadBody));
  for (auto& [vd, loc] : inLoop.found) {
    c.rep.Error(loc, "the loop of kernel '" + kernel + "' writes '" + vd->getNameAsString() + "', declared before the loop: every iteration (a thread) would write one variable",
                "declare it inside the loop, or reduce it (x += v, x -= v, x = std::min(x, v), x = std::max(x, v))");
    ok = false;
  }
  struct Returns : RecursiveASTVisitor<Returns> {
    std::vector<SourceLocation> found;
    bool VisitReturnStmt(ReturnStmt* r) { found.push_back(r->getReturnLoc()); return true; }
    bool TraverseLambdaExpr(LambdaExpr*) { return true; }
  };
  for (auto* s : before) {
    Returns r;
    r.TraverseStmt(const_cast<Stmt*>(s));
    for (auto loc : r.found) {
      c.rep.GpuError(loc, "'return' before the loop nest of kernel '" + kernel + "': on the GPU the nest's threads would run anyway",
                  "test the condition in the control function before calling the kernel, or inside the loop");
      ok = false;
    }
  }
  (void)after;  // a 'return' after the nest ends the statements after it on both
  return ok;
}

void AnalyzeKernel(Context& c, const CXXMethodDecl* md, const FunctionDecl* def) {
  Kernel k;
  k.name = md->getNameAsString();
  k.dims = IpvDims(k.name);
  k.rtv = k.dims == 0;
  k.sourceFile = BaseName(FileOf(c.ctx, def->getLocation()));
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
  for (unsigned i = 0; i < def->getNumParams(); ++i) k.cppParamsDecl += (i ? ", " : "") + ParamDecl(c.ctx, md->getParamDecl(i), def->getParamDecl(i), i);
  GlslPrinter printer(c.ctx, c.cls, c.rep);
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
    // [statements before] N perfectly nested loops [statements after]: the first for loop of the
    // body is the nest; what comes before and after it (the paper's loop_start and loop_end) runs
    // on one thread. The declarations before it are also evaluated by every thread.
    const ForStmt* outer = nullptr;
    for (auto* s : body->body()) {
      if (isa<NullStmt>(s)) continue;
      if (!outer && isa<ForStmt>(s)) outer = cast<ForStmt>(s);
      else (outer ? after : before).push_back(s);
    }
    for (auto* s : before)
      if (isa<DeclStmt>(s)) preamble.push_back(s);
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
      threadParams.push_back({loop.glslType, GlslPrinter::SafeName(loop.var)});
      cur = fs->getBody();
      if (d + 1 < k.dims)
        if (auto* cs = dyn_cast<CompoundStmt>(cur); cs && cs->size() == 1) cur = cs->body_front();
    }
    threadBody = cur;
    // Thread ids are listed innermost first (x), like the dispatch.
    std::reverse(threadParams.begin(), threadParams.end());
    for (unsigned d = 0; d < k.dims; ++d) k.threadAxes.push_back(d);
  }

  // Reductions and member writes.
  WriteScanner ws(c);
  ws.TraverseStmt(const_cast<Stmt*>(threadBody));
  for (auto* s : preamble) ws.TraverseStmt(const_cast<Stmt*>(s));
  WriteScanner ends(c);  // the statements around the loop nest, which one thread runs
  ends.singleThread = true;
  for (auto* list : {&before, &after})
    for (auto* s : *list)
      if (!isa<DeclStmt>(s)) ends.TraverseStmt(const_cast<Stmt*>(s));
  std::set<const VarDecl*> beforeLocals;
  for (auto* s : preamble)
    for (auto* d : cast<DeclStmt>(s)->decls())
      if (auto* vd = dyn_cast<VarDecl>(d)) beforeLocals.insert(vd);
  LocalReductionScanner localReductions(c, beforeLocals);
  localReductions.TraverseStmt(const_cast<Stmt*>(threadBody));
  if (!CheckLoopEnds(c, k.name, before, after, threadBody, localReductions.targets)) return;
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
    for (auto* d : cast<DeclStmt>(s)->decls()) {
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
      r.glslType = GlslTypeOf(vd->getType()).value_or("float");
      r.identity = Identity(r.op, r.glslType);
      r.local = true;
      r.cppType = vd->getType().getUnqualifiedType().getAsString(c.ctx.getPrintingPolicy());
      printer.renames[vd] = r.member + "Local";
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
    r.glslType = GlslTypeOf(field->getType()).value_or("float");
    r.identity = Identity(op, r.glslType);
    printer.renames[field] = r.member + "Local";
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
  for (auto& [field, loc] : ends.appends) ws.appends.emplace(field, loc);

  // GLSL: the thread function.
  std::ostringstream os;
  os << "// from " << c.cls->getNameAsString() << "::" << k.name << " (" << k.sourceFile << ")\n";
  os << (k.returnsBool ? "bool " : "void ") << k.name << "(";
  for (size_t i = 0; i < threadParams.size(); ++i) os << (i ? ", " : "") << threadParams[i].first << " " << threadParams[i].second;
  os << ")\n{\n";
  for (auto* s : preamble)
    if (!reductionDecls.count(s)) os << printer.Stmt(s, 1);
  if (auto* cs = dyn_cast<CompoundStmt>(threadBody))
    for (auto* s : cs->body()) os << printer.ThreadBody(s, 1, !k.rtv);
  else
    os << printer.ThreadBody(threadBody, 1, !k.rtv);
  os << "}\n";
  k.glslBody = os.str();
  // The statements around the loop nest, as functions one thread runs before and after the others.
  if (std::any_of(before.begin(), before.end(), [](const Stmt* s) { return !isa<DeclStmt>(s); }) || !after.empty()) {
    const auto sizeReadsInLoop = printer.sizeReads;  // after the loop a vector's final size is known
    const auto renames = printer.renames;
    for (auto& r : k.reductions)
      for (auto* f : ClassFields(c.cls))
        if (f->getNameAsString() == r.member) printer.renames.erase(f);  // the member itself, not a thread's part
    for (auto& [vd, op] : localReductions.reductions) printer.renames.erase(vd);
    printer.singleThread = true;
    const std::string from = "// from " + c.cls->getNameAsString() + "::" + k.name + " (" + k.sourceFile + "): ";
    if (std::any_of(before.begin(), before.end(), [](const Stmt* s) { return !isa<DeclStmt>(s); })) {
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
          const std::string total = r.member + "Partials[0]";
          const std::string combined = r.op == ReduceOp::Min ? "min(" + r.member + ", " + total + ")"
                                       : r.op == ReduceOp::Max ? "max(" + r.member + ", " + total + ")" : r.member + " + " + total;
          k.glslFinish += "  if (" + anyThreads + ")\n    " + r.member + " = " + combined + ";  // the threads' total\n";
        }
      for (auto* s : after) k.glslFinish += printer.Stmt(s, 1);
      k.glslFinish += "}\n";
    }
    printer.singleThread = false;
    printer.renames = renames;
    for (auto* f : printer.emptiedVectors)
      if (!c.appended.count(f->getNameAsString()))
        c.rep.GpuError(f->getLocation(), "kernel '" + k.name + "' empties '" + f->getNameAsString() + "', which no kernel appends to: on the GPU only an appended vector's size is counted there",
                    "empty it in the control function (before the kernel), or append to it with push_back in the loop");
    printer.sizeReads = sizeReadsInLoop;
  }
  std::map<const FieldDecl*, SourceLocation> appends = ws.appends;
  for (auto* helper : printer.helpers) {
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
  reached.insert(reached.end(), printer.helpers.begin(), printer.helpers.end());
  AddLockedCopies(c, reached);
  // Threads append in any order: a size read in the same kernel would see a partial count.
  CheckObjectSizeReads(c.rep, printer);
  for (auto& [field, loc] : printer.sizeReads)
    if (appends.count(field))
      c.rep.Error(loc, "kernel '" + k.name + "' reads the size of '" + field->getNameAsString() + "', which it appends to",
                  "the final size is known after the kernel: read it in a later kernel, or after the control function returns");
  k.structList = printer.Structs();
  k.constantList = printer.Constants();
  k.functionList = printer.Functions();
  k.atomics = printer.usesAtomics;
  k.floatAtomics = printer.usesFloatAtomics;
  if (!printer.virtualCalls.empty()) AnalyzeVirtualCalls(c, k, printer);
  k.composedCalls = printer.composedCalls;
  for (auto& [holder, method] : printer.composedCalls) {
    if (std::any_of(c.model.compositions.begin(), c.model.compositions.end(), [&](const Composition& x) { return x.holder == holder; }))
      continue;
    Composition comp;
    comp.holder = holder;
    for (auto* f : ClassFields(c.cls))
      if (auto* rd = f->getNameAsString() == holder ? PolymorphicPointee(f->getType()) : nullptr) comp.interfaceName = rd->getNameAsString();
    comp.implName = c.compositions.count(comp.interfaceName) ? c.compositions.at(comp.interfaceName) : "";
    c.model.compositions.push_back(comp);
  }
  for (auto* f : printer.memberVectors) {
    k.memberVectors.push_back(f->getNameAsString());
    if (auto* m = FindMember(c.model, f->getNameAsString())) m->usedByKernels = true;
    RequireReachable(c.rep, f, c.cls);
  }
  std::sort(k.memberVectors.begin(), k.memberVectors.end());
  k.ownFunctionList = k.functionList;
  k.ownMemberVectors = k.memberVectors;
  // Images and samplers, in declaration order so that bindings stay stable across regenerations.
  for (auto* f : ClassFields(c.cls)) {
    const bool loaded = printer.loadedImages.count(f), stored = printer.storedImages.count(f);
    const bool sampled = printer.sampledImages.count(f), sampler = printer.samplers.count(f);
    if (!(loaded || stored || sampled || sampler || printer.sizedImages.count(f))) continue;
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
    const bool loaded = printer.loadedImages.count(p), stored = printer.storedImages.count(p);
    if (loaded || stored) k.images.push_back({p->getNameAsString(), ImageUse::Storage, loaded, stored, true});
    if (printer.sampledImages.count(p)) k.images.push_back({p->getNameAsString(), ImageUse::Texture, false, false, true});
  }
  for (auto& [image, sampler] : printer.samplePairs)
    (isa<FieldDecl>(image) ? k.samplePairs : k.paramSamplePairs).push_back({image->getNameAsString(), sampler->getNameAsString()});
  for (auto* f : ClassFields(c.cls)) {
    if (!printer.textureArrays.count(f)) continue;
    RequireReachable(c.rep, f, c.cls);
    if (auto* m = FindMember(c.model, f->getNameAsString())) {
      m->usedByKernels = true;
      k.textureArrays.push_back(m->name);
    }
  }
  std::sort(k.samplePairs.begin(), k.samplePairs.end());
  for (auto* f : printer.plainMembers) {
    auto* m = FindMember(c.model, f->getNameAsString());
    if (m) m->usedByKernels = true;
    if (m && !m->inClassData && f->getAccess() != AS_private)
      c.rep.GpuError(f->getLocation(), "member '" + f->getNameAsString() + "' of type '" + f->getType().getAsString(c.ctx.getPrintingPolicy()) + "' has a C++ layout that a GPU buffer cannot reproduce",
                  "use int instead of bool, float4x4 instead of float3x3, or reorder struct fields so 16-byte types come first");
    RequireReachable(c.rep, f, c.cls);
  }
  for (auto& r : k.reductions)
    if (auto* m = r.local ? nullptr : FindMember(c.model, r.member)) { m->usedByKernels = true; m->writtenByKernels = true; }

  // CPU backend: the loop nest as the user wrote it, reduction targets renamed.
  if (!k.rtv) {
    Rewriter rw(c.ctx.getSourceManager(), c.ctx.getLangOpts());
    // Reduction targets get their per-thread names; appends go through a lock.
    struct Renamer : RecursiveASTVisitor<Renamer> {
      Rewriter& rw; const std::map<const FieldDecl*, ReduceOp>& red;
      Renamer(Rewriter& r, const std::map<const FieldDecl*, ReduceOp>& m) : rw(r), red(m) {}
      bool VisitMemberExpr(MemberExpr* me) {
        auto* f = dyn_cast<FieldDecl>(me->getMemberDecl());
        if (f && red.count(f) && me->isImplicitAccess()) rw.ReplaceText(me->getMemberLoc(), f->getName().size(), f->getNameAsString() + "Local");
        else if (f && red.count(f)) rw.ReplaceText(me->getSourceRange(), f->getNameAsString() + "Local");
        return true;
      }
    } renamer(rw, ws.reductions);
    const ForStmt* outer = nullptr;
    for (auto* s : body->body())
      if ((outer = dyn_cast<ForStmt>(s))) break;
    renamer.TraverseStmt(const_cast<ForStmt*>(outer));
    // A flag every thread may set: stored atomically, so that the threads do not race on it.
    for (auto* bo : ws.constantStoreExprs) {
      SourceLocation end = Lexer::findLocationAfterToken(bo->getEndLoc(), tok::semi, c.ctx.getSourceManager(), c.ctx.getLangOpts(), false);
      if (end.isInvalid()) continue;
      rw.InsertTextBefore(bo->getBeginLoc(), "{\n#pragma omp atomic write\n");
      rw.InsertTextAfter(end, "\n}");
    }
    LockAppends(rw, outer);
    // A loop whose body is a bare statement ends before its ';': take the ';' too.
    SourceLocation end = Lexer::findLocationAfterToken(outer->getEndLoc(), tok::semi, c.ctx.getSourceManager(), c.ctx.getLangOpts(), false);
    k.cpuLoopNest = CanonicalCode(end.isValid() ? rw.getRewrittenText(CharSourceRange::getCharRange(outer->getBeginLoc(), end))
                                                : rw.getRewrittenText(outer->getSourceRange()));
    if (c.model.forCpu) CopySourceDeclarations(c, def->getBody(), "kernel '" + k.name + "'");  // the CPU class copies the loop nest
    for (auto* s : before) k.cpuPreamble += StatementText(c, s) + "\n";
    k.cpuPreamble = CanonicalCode(k.cpuPreamble);
    for (auto* s : after) k.cpuPostamble += StatementText(c, s) + "\n";
    k.cpuPostamble = CanonicalCode(k.cpuPostamble);
  }
  c.model.kernels.push_back(k);
}

// ---- control functions -----------------------------------------------------

// Kernel calls, and library calls that work on member vectors (scan, fill, memcpy): either makes
// a member function a control function.
bool IsPerThreadFunction(const CXXMethodDecl* md, const CXXRecordDecl* cls);

struct KernelCallFinder : RecursiveASTVisitor<KernelCallFinder> {
  const CXXRecordDecl* cls;  // a call of its per-thread functions counts too (they call kernels)
  std::vector<const Expr*> calls;
  explicit KernelCallFinder(const CXXRecordDecl* c) : cls(c) {}
  bool VisitCXXMemberCallExpr(CXXMemberCallExpr* call) {
    auto* md = call->getMethodDecl();
    if (md && (IsKernelName(md->getName()) || IsPerThreadFunction(md, cls)) && isa<CXXThisExpr>(call->getImplicitObjectArgument()->IgnoreParenImpCasts()))
      calls.push_back(call);
    return true;
  }
  bool VisitCallExpr(CallExpr* call) {
    auto* fd = call->getDirectCallee();
    static const std::set<std::string> library = {"exclusive_scan", "inclusive_scan", "fill", "memcpy", "memmove", "sort"};
    if (!fd || !fd->isInStdNamespace() || !library.count(fd->getNameAsString()) || isa<CXXMemberCallExpr>(call)) return true;
    for (auto* arg : call->arguments()) {
      auto* mc = dyn_cast<CXXMemberCallExpr>(arg->IgnoreParenImpCasts());
      if (auto* bo = dyn_cast<BinaryOperator>(arg->IgnoreParenImpCasts())) mc = dyn_cast<CXXMemberCallExpr>(bo->getLHS()->IgnoreParenImpCasts());
      if (mc && ThisField(mc->getImplicitObjectArgument()) && IsStdVector(ThisField(mc->getImplicitObjectArgument())->getType())) {
        calls.push_back(call);
        break;
      }
    }
    return true;
  }
};

// kernel_slicer's per-thread function: a member function (not a kernel) that calls kernel_ functions
// with a parameter of its own as the thread id, `void Run(uint tid, ...) { float t; kernel_A(tid, &t); ... }`.
// A ...Block control function runs it in a thread loop; it is no control function itself.
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
      c.rep.GpuError(loc, "control function '" + control + "' changes Image2D parameter '" + p->getNameAsString() + "' on the host ('" + md->getNameAsString() + "')",
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

class ControlRewriter {
public:
  ControlRewriter(Context& c, const CXXMethodDecl* md, const FunctionDecl* def, Control& ctrl)
      : m_c(c), m_md(md), m_def(def), m_ctrl(ctrl),
        m_gpu(c.ctx.getSourceManager(), c.ctx.getLangOpts()), m_cpu(c.ctx.getSourceManager(), c.ctx.getLangOpts()) {}

  void Run() {
    CheckAppendedUses();
    RemoveOpenMpPragmas();
    Visit(m_def->getBody());
    CheckTemporaryUses();
    m_ctrl.vulkanCmdBody = CanonicalCode(m_gpu.getRewrittenText(m_def->getBody()->getSourceRange()));
    m_ctrl.cpuBody = CanonicalCode(m_cpu.getRewrittenText(m_def->getBody()->getSourceRange()));
  }

private:
  // The user's `#pragma omp ...` lines go: on the GPU the loops they parallelise become dispatches,
  // and the CPU class puts its own pragma on each thread loop.
  void RemoveOpenMpPragmas() {
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

  // A pointer argument of a kernel call, as the BufferView the generated code binds.
  std::string BufferArg(const Expr* arg) {
    const Expr* e = arg->IgnoreParenImpCasts();
    if (auto* dr = dyn_cast<DeclRefExpr>(e))
      if (auto* p = dyn_cast<ParmVarDecl>(dr->getDecl()); p && p->getDeclContext() == m_def)
        return "m_inOut_" + m_ctrl.name + "." + p->getNameAsString();
    const Expr* offset = nullptr;
    if (auto* bo = dyn_cast<BinaryOperator>(e); bo && bo->getOpcode() == BO_Add) {
      offset = bo->getRHS();
      e = bo->getLHS()->IgnoreParenImpCasts();
    }
    if (auto* mc = dyn_cast<CXXMemberCallExpr>(e); mc && mc->getMethodDecl()->getName() == "data") {
      if (auto* f = ThisField(mc->getImplicitObjectArgument()); f && IsStdVector(f->getType())) {
        if (auto* m = FindMember(m_c.model, f->getNameAsString())) m->usedByKernels = true;
        std::string view = "m_vdata." + f->getNameAsString() + ".View(";
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
          std::string view = "m_temporaries." + t->buffer + ".View(";
          if (offset) view += "sizeof(" + t->cppType + ") * size_t(" + m_c.Text(offset->getSourceRange()) + ")";
          return view + ")";
        }
    m_c.rep.GpuError(arg->getBeginLoc(), "pointer argument of a kernel call must be a parameter of '" + m_ctrl.name + "', 'member.data()' or a local std::vector's data() (+ offset)",
                  "pass the control function's size-annotated pointer, a std::vector member's data(), or a std::vector declared in '" + m_ctrl.name + "'");
    return "{}";
  }

  // ---- std::vector locals passed to kernels: std::vector<float> temp(n[, value]); kernel1D_A(temp.data(), ...) ----
  // On the GPU the local gets a device buffer of the generated class (m_temporaries), sized and
  // filled where the local is declared, as its constructor fills the host's. The host's vector
  // stays (its size() is the buffer's); its elements are never the GPU's, so the control function
  // may only pass data() to kernels and ask for size().

  std::map<const VarDecl*, Control::LocalBuffer> m_temporaries;
  std::set<const DeclRefExpr*> m_temporaryUses;  // the references a kernel argument or size() makes

  const Control::LocalBuffer* Temporary(const VarDecl* vd) {
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
      m_c.rep.GpuError(vd->getLocation(), "std::vector '" + local + "' is passed to a kernel, but the GPU's copy of a local vector is made only from 'std::vector<T> " + local +
                       "(n)' or '(n, value)' declared on its own at the top of '" + m_ctrl.name + "'",
                       "declare it as 'std::vector<T> " + local + "(n);' at the top of the function, or make it a member");
      return nullptr;
    }
    const ASTContext& ctx = m_c.ctx;
    if (args == 2 && ctx.getTypeSize(element) != 32) {
      m_c.rep.GpuError(ctor->getArg(1)->getBeginLoc(), "the GPU fills a local vector with a value of 32 bits, not of " + std::to_string(ctx.getTypeSize(element)) + " bits",
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
                          "  crossrt::EnsureSize(m_ctx, m_temporaries." + t.buffer + ", " + bytes + ");\n"
                          "  crossrt::FillCmd(a_cmd, m_temporaries." + t.buffer + ".View(), (" + bytes + " + 3) / 4 * 4, " + bits + ");");
    m_ctrl.temporaries.push_back(t);
    return &m_temporaries.emplace(vd, t).first->second;
  }

  // A temporary's elements live on the GPU: the host's copy is not theirs to read or write.
  void CheckTemporaryUses() {
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
        rw.m_c.rep.GpuError(dr->getLocation(), "'" + it->second.local + "' is used on the host, but the kernels of '" + rw.m_ctrl.name +
                            "' read and write its GPU copy", "pass " + it->second.local + ".data() only to kernels; to read the results make it a member "
                            "(or a size-annotated parameter), which the generated class copies back");
        return true;
      }
    } uses(*this);
    if (!m_temporaries.empty()) uses.TraverseStmt(const_cast<Stmt*>(m_def->getBody()));
  }

  // An Image2D argument of a kernel call, as the crossrt::ImageView the generated code binds: the
  // device copy of a parameter of the control function, or of a member.
  std::string ImageArg(const ParmVarDecl* p, const Expr* arg) {
    const Expr* e = arg->IgnoreParenImpCasts();
    if (auto* dr = dyn_cast<DeclRefExpr>(e))
      if (auto* cp = dyn_cast<ParmVarDecl>(dr->getDecl()); cp && cp->getDeclContext() == m_def)
        return "m_inOut_" + m_ctrl.name + "." + cp->getNameAsString();
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
      return "crossrt::ImageView(m_images." + name + ", m_images." + name + "Width, m_images." + name + "Height)";
    }
    m_c.rep.GpuError(arg->getBeginLoc(), "Image2D argument of a kernel call must be an Image2D parameter of '" + m_ctrl.name + "' or an Image2D member",
                  "an image local to '" + m_ctrl.name + "' has no GPU copy: make it a member (its GPU copy is kept between calls) or a parameter of '" +
                      m_ctrl.name + "'");
    return "{}";
  }

  std::string Args(const CXXMemberCallExpr* call, bool skipThreadIds) {
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
    }
    return out;
  }

  // A parameter that some thread loop passes a local's address to holds one value per thread on the
  // GPU; a buffer passed to it elsewhere would be read one element per thread, not as C++ reads it.
  void CheckNotThreadState(const CXXMethodDecl* md, const ParmVarDecl* p, const Expr* arg) {
    if (!m_c.threadState.count({md->getNameAsString(), p->getNameAsString()})) return;
    m_c.rep.GpuError(arg->getBeginLoc(), "parameter '" + p->getNameAsString() + "' of '" + md->getNameAsString() +
                  "' gets a local's address in a thread loop, so on the GPU it holds one value per thread, but here it is given a buffer",
                  "pass the address of a local declared in the thread loop everywhere, or give the kernel a separate buffer parameter");
  }

  void Note(const CXXMemberCallExpr* call) {
    std::string n = call->getMethodDecl()->getNameAsString();
    if (std::find(m_ctrl.kernelsCalled.begin(), m_ctrl.kernelsCalled.end(), n) == m_ctrl.kernelsCalled.end())
      m_ctrl.kernelsCalled.push_back(n);
  }

  // ---- thread loops: for (y) for (x) { locals; kernel_A(x, y, &local); for (host) kernel_B(...); } ----
  // Several kernels per thread, sharing per-thread locals (paper 2.1 and 4.4). Both execution modes are
  // recorded: the megakernel (one shader runs the whole body) and wavefront (one dispatch per kernel
  // call, the locals kept in buffers between them); the generated class picks one at run time.

  struct ThreadLoop {
    std::vector<LoopHeader> loops;                 // outermost first
    std::map<const VarDecl*, unsigned> axisOf;     // loop variable -> thread axis
    std::vector<std::pair<const VarDecl*, std::string>> stateBuffers;  // per-thread local -> its wavefront buffer
    std::vector<std::string> bufferArgs;           // host BufferView of each megakernel parameter so far
    std::set<const VarDecl*> locals;               // every local of the body (per-thread)
    std::set<const VarDecl*> passed;               // locals some kernel call gets the address of
    std::vector<const VarDecl*> outer;             // control-function variables the body reads, first read first
    Kernel mega;                                   // the megakernel, without its kernels' code yet
    std::string hostArgs;                          // ...Cmd arguments of the megakernel after the counts
    std::string counts;                            // ", (w), (h)": threads per axis, x first
    bool megakernelOnly = false;                   // a kernel's result ends a thread's loop: no wavefront form
    bool ok = true;
  };

  // ---- kernel_slicer's per-thread functions: for (i) Run(i, args) with Run(tid, ...) calling kernels ----
  // A thread loop whose body calls such a function is the function's body with its parameters bound
  // to the call's arguments (`m_inlined`): Resolve() reads through them.
  std::map<const ParmVarDecl*, const Expr*> m_inlined;
  const Expr* Resolve(const Expr* e) const {
    auto* dr = dyn_cast<DeclRefExpr>(e->IgnoreCasts()->IgnoreParens());
    auto* p = dr ? dyn_cast<ParmVarDecl>(dr->getDecl()) : nullptr;
    auto it = p ? m_inlined.find(p) : m_inlined.end();
    return it == m_inlined.end() ? e : Resolve(it->second);
  }
  // The source text of an argument, read through per-thread functions' parameters.
  std::string ResolvedText(const Expr* e) { return m_c.Text(Resolve(e)->getSourceRange()); }

  // Variables passed as thread ids to RTV kernels anywhere inside `s`.
  std::set<const VarDecl*> ThreadIdVars(const Stmt* s) {
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

  bool TryThreadLoop(const ForStmt* outerLoop) {
    // The innermost body a call of a per-thread function (kernel_slicer's ...Block form)? Then the
    // thread loop's body is that function's, its parameters bound to the call's arguments.
    m_inlined.clear();
    const Stmt* innermost = outerLoop;
    while (auto* fs = dyn_cast_or_null<ForStmt>(innermost)) innermost = SingleStatement(fs->getBody());
    const FunctionDecl* perThread = nullptr;
    if (auto* e = dyn_cast_or_null<Expr>(innermost))
      if (auto* call = dyn_cast<CXXMemberCallExpr>(e->IgnoreImplicit()); call && IsPerThreadFunction(call->getMethodDecl(), m_c.cls)) {
        call->getMethodDecl()->hasBody(perThread);
        for (unsigned i = 0; i < call->getNumArgs() && i < perThread->getNumParams(); ++i) m_inlined[perThread->getParamDecl(i)] = call->getArg(i);
      }
    const std::set<const VarDecl*> idVars = ThreadIdVars(perThread ? perThread->getBody() : outerLoop);
    ThreadLoop tl;
    const Stmt* body = outerLoop;
    while (auto* fs = dyn_cast_or_null<ForStmt>(body)) {
      LoopHeader h;
      if (!QuietParseLoop(fs, h) || !idVars.count(h.var)) break;
      tl.loops.push_back(h);
      body = SingleStatement(fs->getBody());
    }
    if (tl.loops.empty()) {
      m_inlined.clear();
      return false;
    }
    if (perThread && body == innermost) body = perThread->getBody();
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

    const unsigned index = ++m_threadLoops;
    tl.mega.name = m_ctrl.name + "_Megakernel" + (index > 1 ? std::to_string(index) : "");
    tl.mega.rtv = true;
    tl.mega.megakernelOf = m_ctrl.name;
    tl.mega.sourceFile = m_ctrl.sourceFile;
    tl.mega.dims = unsigned(tl.loops.size());
    GlslPrinter printer(m_c.ctx, m_c.cls, m_c.rep);
    for (auto& s : ClassStructNames(m_c.model)) printer.predeclaredStructs.insert(s);
    for (auto& [param, arg] : m_inlined) printer.renames[param] = printer.Expr(Resolve(arg));  // read through
    std::string glsl = ThreadBodyGlsl(tl, printer, body, 1);
    if (!tl.ok) return true;
    for (auto* f : printer.plainMembers)
      if (auto* m = FindMember(m_c.model, f->getNameAsString())) m->usedByKernels = true;
    if (!printer.memberVectors.empty() || !printer.helpers.empty())
      Error(tl, outerLoop->getBeginLoc(), "the host code of a thread loop of '" + m_ctrl.name + "' uses member vectors or calls functions",
            "count host loops with plain members, parameters or constants; move other work into a kernel");
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
      id.glslName = GlslPrinter::SafeName(id.name);
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
      v.glslName = GlslPrinter::SafeName(v.name);
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
    const std::string wavefront = ThreadBodyCpp(tl, body);  // after the counts
    tl.mega.glslBody = "// from " + m_c.cls->getNameAsString() + "::" + m_ctrl.name + " (" + m_ctrl.sourceFile +
                       "): the body of its thread loop, each kernel call a function call\nvoid " + tl.mega.name + "(" + signature + ")\n{\n" + glsl + "}\n";
    m_c.model.megakernels.push_back(tl.mega);

    // Vulkan: both modes, picked when recording.
    std::string states;
    for (auto& [local, buffer] : tl.stateBuffers) {
      if (!tl.passed.count(local)) continue;  // no kernel sees it: nothing to keep between dispatches
      std::string cppType = CppTypeName(m_c.ctx, local->getType().getUnqualifiedType());
      m_ctrl.threadStates.push_back({buffer, cppType, local->getNameAsString()});
      states += "crossrt::EnsureSize(m_ctx, m_threadState." + buffer + ", sizeof(" + cppType + ") * std::max<size_t>(1, crt_threads));\n"
                "crossrt::FillCmd(a_cmd, m_threadState." + buffer + ".View(), sizeof(" + cppType + ") * crt_threads, 0);  // " +
                local->getNameAsString() + " starts at zero\n";
    }
    std::string threads;
    for (auto& h : tl.loops) threads += (threads.empty() ? "" : " * ") + std::string("size_t(") + CountExpr(m_c, h) + ")";
    std::string text =
        "if (m_executionMode == crossrt::ExecutionMode::Megakernel)  // the whole loop body in one shader\n" + tl.mega.name + "Cmd(a_cmd" + tl.counts + tl.hostArgs +
        ");\nelse  // wavefront: one dispatch per kernel call, each thread's locals in buffers between them\n{\nconst size_t crt_threads = " + threads + ";\n" + states +
        wavefront + "}\n";
    if (tl.megakernelOnly) {
      m_ctrl.threadStates.erase(m_ctrl.threadStates.end() - long(std::count_if(tl.stateBuffers.begin(), tl.stateBuffers.end(),
                                                                               [&](const auto& x) { return tl.passed.count(x.first) > 0; })),
                                m_ctrl.threadStates.end());
      text = "// A kernel's result ends a thread's loop here, at a time of the thread's own: the whole loop\n"
             "// body runs in one shader (the megakernel) in both execution modes.\n" +
             tl.mega.name + "Cmd(a_cmd" + tl.counts + tl.hostArgs + ");\n";
    }
    SourceLocation end = Lexer::findLocationAfterToken(outerLoop->getEndLoc(), tok::semi, m_c.ctx.getSourceManager(), m_c.ctx.getLangOpts(), false);
    CharSourceRange range = end.isValid() ? CharSourceRange::getCharRange(outerLoop->getBeginLoc(), end) : CharSourceRange::getTokenRange(outerLoop->getSourceRange());
    m_gpu.ReplaceText(range, text);
    // CPU: the loop as written, its threads on all cores (the locals are private to each iteration).
    unsigned col = m_c.ctx.getSourceManager().getExpansionColumnNumber(outerLoop->getBeginLoc());
    std::string pragma = "#pragma omp parallel for schedule(dynamic, 16)";
    if (tl.loops.size() > 1) pragma += " collapse(" + std::to_string(tl.loops.size()) + ")";
    m_cpu.InsertTextBefore(outerLoop->getBeginLoc(), pragma + "\n" + std::string(col > 0 ? col - 1 : 0, ' '));
    m_inlined.clear();
    return true;
  }

  static std::string StateBuffer(const ThreadLoop& tl, const VarDecl* vd) {
    for (auto& [local, buffer] : tl.stateBuffers)
      if (local == vd) return buffer;
    return "";
  }

  void Error(ThreadLoop& tl, SourceLocation loc, const std::string& message, const std::string& hint) {
    m_c.rep.GpuError(loc, message, hint);
    tl.ok = false;
  }

  // Checks that `e` does not depend on the thread (host code and by-value kernel arguments run once
  // for all threads in wavefront mode) and collects the control function's variables it reads.
  void CheckUniform(ThreadLoop& tl, const Expr* e, const std::string& where, bool readOnGpu = true) {
    struct Finder : RecursiveASTVisitor<Finder> {
      std::vector<const DeclRefExpr*> refs;
      bool VisitDeclRefExpr(DeclRefExpr* dr) { refs.push_back(dr); return true; }
    } finder;
    finder.TraverseStmt(const_cast<Expr*>(e));
    for (auto* dr : finder.refs) {
      if (auto* p = dyn_cast<ParmVarDecl>(dr->getDecl()); p && m_inlined.count(p)) {  // a per-thread function's parameter
        CheckUniform(tl, m_inlined.at(p), where, readOnGpu);
        continue;
      }
      auto* vd = dyn_cast<VarDecl>(dr->getDecl());
      if (!vd || (vd->hasGlobalStorage() && !vd->isStaticLocal())) continue;
      bool isLoopVar = std::any_of(tl.loops.begin(), tl.loops.end(), [&](const LoopHeader& h) { return h.var == vd; });
      if (isLoopVar || !StateBuffer(tl, vd).empty() || (tl.locals.count(vd) && !m_hostLoopVars.count(vd)))
        Error(tl, dr->getBeginLoc(), "'" + vd->getNameAsString() + "' differs from thread to thread, but " + where + " in the thread loop of '" + m_ctrl.name +
              "' runs once for all threads in wavefront mode", "pass per-thread values to kernels by address (&" + vd->getNameAsString() + ") and branch inside the kernels");
      else if (readOnGpu && !tl.locals.count(vd) && std::find(tl.outer.begin(), tl.outer.end(), vd) == tl.outer.end())
        tl.outer.push_back(vd);
    }
  }

  // The GLSL of the thread loop's body (the megakernel) and, alongside, the checks of what may be in it.
  std::string ThreadBodyGlsl(ThreadLoop& tl, GlslPrinter& printer, const Stmt* s, int indent) {
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
        auto* construct = init ? dyn_cast<CXXConstructExpr>(init->IgnoreImplicit()) : nullptr;
        if (init && !(construct && construct->getNumArgs() == 0)) {
          Error(tl, vd->getLocation(), "per-thread local '" + vd->getNameAsString() + "' of the thread loop of '" + m_ctrl.name + "' has an initializer",
                "declare it without one (it starts at zero on the GPU, as LiteMath types do) and set it in the first kernel");
          continue;
        }
        auto g = GlslTypeOf(vd->getType());
        if (!g || vd->getType()->isArrayType() || vd->getType()->isPointerType()) {
          Error(tl, vd->getLocation(), "per-thread local '" + vd->getNameAsString() + "' of type '" + vd->getType().getAsString(m_c.ctx.getPrintingPolicy()) +
                "' has no GPU equivalent", "use int, uint, float, LiteMath types or plain structs of those; keep arrays in a struct");
          continue;
        }
        tl.stateBuffers.push_back({vd, m_ctrl.name + (m_threadLoops > 1 ? std::to_string(m_threadLoops) : "") + "_" + vd->getNameAsString()});
        static const std::regex zeroable(R"(^(float|int|uint|[iu]?vec[234]|mat[234])$)");
        std::string name = GlslPrinter::SafeName(vd->getNameAsString());
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
      std::string header = "for (" + *GlslTypeOf(var->getType()) + " " + GlslPrinter::SafeName(var->getNameAsString()) + " = " + printer.Expr(var->getInit()) + "; " +
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
      const bool leaves = then && (isa<BreakStmt>(then) || isa<ContinueStmt>(then));
      if (!kernelCall || !kernelCall->getMethodDecl() || !kernelCall->getMethodDecl()->getReturnType()->isBooleanType() || !leaves ||
          is->getElse() || m_hostLoopDepth == 0) {
        Error(tl, s->getBeginLoc(), "the thread loop of '" + m_ctrl.name + "' may branch only on a kernel's bool result, to leave a loop inside it",
              "write if (!kernel_X(tid, ...)) break; (or continue) in a counted loop of the thread loop, and branch on anything else inside the kernels");
        return "";
      }
      tl.megakernelOnly = true;
      return pad + "if (" + (negated ? "!" : "") + KernelCallGlsl(tl, printer, kernelCall) + ")\n" + pad + "  " +
             (isa<BreakStmt>(then) ? "break;\n" : "continue;\n");
    }
    auto* call = dyn_cast<CXXMemberCallExpr>(s);
    auto* md = call ? call->getMethodDecl() : nullptr;
    if (!md || !IsKernelName(md->getName()) || IpvDims(md->getName()) || !isa<CXXThisExpr>(call->getImplicitObjectArgument()->IgnoreParenImpCasts())) {
      Error(tl, s->getBeginLoc(), "the thread loop of '" + m_ctrl.name + "' may hold only per-thread local declarations, kernel_ calls and counted loops around them",
            "move this code into a kernel: the loop's body runs once per thread, on the GPU");
      return "";
    }
    return pad + KernelCallGlsl(tl, printer, call) + ";\n";
  }

  // A kernel call in the thread loop's body, as the megakernel calls the kernel's thread function.
  std::string KernelCallGlsl(ThreadLoop& tl, GlslPrinter& printer, const CXXMemberCallExpr* call) {
    auto* md = call->getMethodDecl();
    Note(call);
    auto& calls = tl.mega.megakernelCalls;
    if (std::find(calls.begin(), calls.end(), md->getNameAsString()) == calls.end()) calls.push_back(md->getNameAsString());
    std::string args;
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
        std::string name = GlslPrinter::SafeName(vd->getNameAsString());
        a = type == varType ? name : type + "(" + name + ")";
      } else if (IsImageParam(p)) {
        Error(tl, arg->getBeginLoc(), "Image2D argument of '" + md->getNameAsString() + "' in a thread loop that calls several kernels",
              "the megakernel binds members only: make the image a member of the class, or give the kernel a thread loop of its own");
        continue;
      } else if (p->getType()->isPointerType()) {
        auto* vd = AddressedVar(arg);
        if (vd && !StateBuffer(tl, vd).empty()) {
          tl.passed.insert(vd);
          a = GlslPrinter::SafeName(vd->getNameAsString());
        } else if (vd) {
          Error(tl, arg->getBeginLoc(), "'&" + vd->getNameAsString() + "' passed to '" + md->getNameAsString() + "' is not a per-thread local declared in the thread loop",
                "declare the variable inside the thread loop's body");
          continue;
        } else {
          CheckNotThreadState(md, p, arg);
          CheckUniform(tl, arg, "a buffer argument", false);  // bound by the host
          AddMegakernelBuffer(tl, md, p, BufferArg(Resolve(arg)), arg->getBeginLoc());
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
    return md->getNameAsString() + "(" + args + ")";
  }

  // A pointer argument of a kernel in a thread loop: in the megakernel, a buffer named as the
  // kernel's parameter (its code refers to that name). Two kernels naming different buffers alike
  // would collide there.
  void AddMegakernelBuffer(ThreadLoop& tl, const CXXMethodDecl* md, const ParmVarDecl* p, const std::string& hostArg, SourceLocation loc) {
    const KernelParam* kp = nullptr;
    for (auto& k : m_c.model.kernels)
      if (k.name == md->getNameAsString())
        for (auto& x : k.params)
          if (x.name == p->getNameAsString()) kp = &x;
    if (!kp) return;  // the kernel failed analysis (reported there)
    for (unsigned i = 0; i < tl.mega.params.size(); ++i) {
      KernelParam& have = tl.mega.params[i];
      if (have.name != kp->glslName) continue;
      if (tl.bufferArgs[i] != hostArg || have.glslType != kp->glslType)
        Error(tl, loc, "parameter '" + p->getNameAsString() + "' of '" + md->getNameAsString() + "' is given another buffer than a parameter of the same name of another kernel in the thread loop",
              "rename one of them: the megakernel binds each kernel's buffers under the parameter's name");
      have.isConstPointee = have.isConstPointee && kp->isConstPointee;
      return;
    }
    KernelParam b = *kp;
    b.name = kp->glslName;
    tl.mega.params.push_back(b);
    tl.bufferArgs.push_back(hostArg);
    tl.hostArgs += ", " + hostArg;
  }

  // The wavefront version of the thread loop's body: host loops as written, each kernel call a
  // dispatch over all threads, per-thread locals bound as their buffers.
  std::string ThreadBodyCpp(ThreadLoop& tl, const Stmt* s) {
    if (auto* cs = dyn_cast<CompoundStmt>(s)) {
      std::string out;
      for (auto* child : cs->body()) out += ThreadBodyCpp(tl, child);
      return out;
    }
    if (auto* fs = dyn_cast<ForStmt>(s)) {
      // A host loop of a per-thread function runs in the control function: its parameters must be
      // what the control function passes, under the same names.
      struct Refs : RecursiveASTVisitor<Refs> {
        std::vector<const DeclRefExpr*> found;
        bool VisitDeclRefExpr(DeclRefExpr* dr) { found.push_back(dr); return true; }
      } refs;
      for (const Stmt* part : {fs->getInit(), static_cast<const Stmt*>(fs->getCond()), static_cast<const Stmt*>(fs->getInc())})
        if (part) refs.TraverseStmt(const_cast<Stmt*>(part));
      for (auto* dr : refs.found)
        if (auto* p = dyn_cast<ParmVarDecl>(dr->getDecl()); p && m_inlined.count(p) && ResolvedText(dr) != p->getNameAsString())
          Error(tl, dr->getBeginLoc(), "a loop of '" + cast<FunctionDecl>(p->getDeclContext())->getNameAsString() + "' reads its parameter '" +
                p->getNameAsString() + "', which '" + m_ctrl.name + "' passes as '" + ResolvedText(dr) + "'",
                "pass the values its loops read under the same names");
      return m_c.Text(SourceRange(fs->getBeginLoc(), fs->getRParenLoc())) + "\n{\n" + ThreadBodyCpp(tl, fs->getBody()) + "}\n";
    }
    if (isa<IfStmt>(s)) return "";  // a loop a kernel's result may end: the megakernel only
    auto* call = dyn_cast<CXXMemberCallExpr>(s);
    auto* md = call ? call->getMethodDecl() : nullptr;
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
      args += ", " + (buffer.empty() ? BufferArg(Resolve(arg)) : "m_threadState." + buffer + ".View()");
    }
    return md->getNameAsString() + "Cmd(a_cmd" + tl.counts + args + ");\n";
  }

  // for (...) for (...) kernel_X(tidX, tidY, ...): one dispatch of the whole nest.
  bool TryRtvNest(const ForStmt* outer) {
    std::vector<LoopHeader> loops;
    const Stmt* cur = outer;
    while (auto* fs = dyn_cast_or_null<ForStmt>(cur)) {
      LoopHeader h;
      if (!QuietParseLoop(fs, h)) return false;
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
    SourceLocation end = Lexer::findLocationAfterToken(outer->getEndLoc(), tok::semi, m_c.ctx.getSourceManager(), m_c.ctx.getLangOpts(), false);
    CharSourceRange range = end.isValid() ? CharSourceRange::getCharRange(outer->getBeginLoc(), end) : CharSourceRange::getTokenRange(outer->getSourceRange());
    m_gpu.ReplaceText(range, md->getNameAsString() + "Cmd(a_cmd" + counts + Args(call, true) + ");");
    auto& sm = m_c.ctx.getSourceManager();
    unsigned col = sm.getExpansionColumnNumber(outer->getBeginLoc());
    std::string indent(col > 0 ? col - 1 : 0, ' ');
    std::string pragma = "#pragma omp parallel for schedule(dynamic, 16)";
    if (loops.size() > 1) pragma += " collapse(" + std::to_string(loops.size()) + ")";
    m_cpu.InsertTextBefore(outer->getBeginLoc(), pragma + "\n" + indent);
    return true;
  }

  // The loop shape of ParseLoop, without reporting: `for (int i = a; i < b; ++i)`.
  bool QuietParseLoop(const ForStmt* fs, LoopHeader& h) {
    auto* ds = dyn_cast_or_null<DeclStmt>(fs->getInit());
    if (!ds || !ds->isSingleDecl()) return false;
    h.var = dyn_cast<VarDecl>(ds->getSingleDecl());
    if (!h.var || !h.var->getInit()) return false;
    h.start = h.var->getInit();
    auto* cond = dyn_cast_or_null<BinaryOperator>(fs->getCond() ? fs->getCond()->IgnoreImplicit() : nullptr);
    if (!cond || (cond->getOpcode() != BO_LT && cond->getOpcode() != BO_LE)) return false;
    auto* lhs = dyn_cast<DeclRefExpr>(cond->getLHS()->IgnoreParenImpCasts());
    if (!lhs || lhs->getDecl() != h.var) return false;
    h.end = cond->getRHS();
    h.inclusive = cond->getOpcode() == BO_LE;
    const Expr* inc = fs->getInc() ? fs->getInc()->IgnoreImplicit() : nullptr;
    if (auto* uo = dyn_cast_or_null<UnaryOperator>(inc)) return uo->isIncrementOp();
    if (auto* ca = dyn_cast_or_null<CompoundAssignOperator>(inc)) {
      Expr::EvalResult r;
      return ca->getOpcode() == BO_AddAssign && ca->getRHS()->EvaluateAsInt(r, m_c.ctx) && r.Val.getInt() == 1;
    }
    return false;
  }

  // `m_x = v;` in a control function runs on the host while recording; the kernels recorded
  // around it must see it in order, so the ...Cmd also records an update of the GPU copy (and
  // likewise for the count of a cleared vector that kernels append to).
  void RecordMemberWrite(const Stmt* s) {
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
    m_gpu.InsertTextAfter(end, " UpdateMemberCmd(a_cmd, offsetof(ClassData, " + m->name + "), &" + m->name + ", sizeof(" + m->name + "));");
  }

  // `std::sort(m_v.begin(), m_v.end(), ...)`: the whole of one member vector.
  static bool IsWholeVector(const CallExpr* call) {
    auto* first = dyn_cast<CXXMemberCallExpr>(call->getArg(0)->IgnoreParenImpCasts());
    auto* last = dyn_cast<CXXMemberCallExpr>(call->getArg(1)->IgnoreParenImpCasts());
    if (!first || !last || !first->getMethodDecl() || !last->getMethodDecl()) return false;
    auto* f = ThisField(first->getImplicitObjectArgument());
    return f && f == ThisField(last->getImplicitObjectArgument()) && first->getMethodDecl()->getName() == "begin" &&
           last->getMethodDecl()->getName() == "end";
  }

  // A vector kernels append to has its size on the GPU while the control function records: its host
  // copy is stale until the call returns, so host code may only clear it (or reserve room) and sort
  // all of it, which the GPU does with the count it has.
  void CheckAppendedUses() {
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
        rw.m_c.rep.GpuError(loc, "control function '" + rw.m_ctrl.name + "' uses " + what + " of '" + v +
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

  // `m_v.clear();` of a vector kernels append to: the GPU's count restarts at 0 too, in order with
  // the kernels recorded around it. Both go in one block, so a clear that is the body of an `if`
  // or a loop stays one statement.
  void RecordClear(const Stmt* s) {
    auto* call = dyn_cast_or_null<CXXMemberCallExpr>(s);
    if (!call || !call->getMethodDecl() || call->getMethodDecl()->getName() != "clear") return;
    auto* f = ThisField(call->getImplicitObjectArgument());
    if (!f || !m_c.appended.count(f->getNameAsString())) return;
    SourceLocation end = Lexer::findLocationAfterToken(s->getEndLoc(), tok::semi, m_c.ctx.getSourceManager(), m_c.ctx.getLangOpts(), false);
    if (end.isInvalid()) return;
    const std::string size = f->getNameAsString() + "_size";
    m_gpu.InsertTextBefore(s->getBeginLoc(), "{ ");
    m_gpu.InsertTextAfter(end, " const uint32_t crt_empty = 0; UpdateMemberCmd(a_cmd, offsetof(ClassData, " + size +
                                   "), &crt_empty, sizeof(crt_empty)); }");
  }

  // Another control function would submit its own work while this one is being recorded.
  void CheckNestedControl(const CXXMemberCallExpr* call) {
    auto* md = call->getMethodDecl();
    const FunctionDecl* def = nullptr;
    if (!md || IsKernelName(md->getName()) || !md->hasBody(def) || !def || !IsClassOrBase(md->getParent(), m_c.cls) ||
        IsPerThreadFunction(md, m_c.cls))
      return;
    KernelCallFinder kc(m_c.cls);
    kc.TraverseStmt(def->getBody());
    if (kc.calls.empty()) return;
    m_c.rep.GpuError(call->getBeginLoc(), "control function '" + m_ctrl.name + "' calls control function '" + md->getNameAsString() + "'",
                  "on the GPU each control function is one submission: call its kernels directly here, or call both from outside the class");
  }

  // ---- library calls on device data: std::exclusive_scan/inclusive_scan, memcpy, std::fill ----

  // A position in device data: `m_v.begin()`, `m_v.end()`, `m_v.data()`, a pointer parameter,
  // each optionally `+ k`.
  struct Position {
    std::string view;      // BufferView expression of the start of the underlying buffer
    std::string key;       // which buffer (member or parameter name)
    std::string offset;    // elements from the start ("" for 0)
    QualType element;
    const Member* vector = nullptr;
    bool isEnd = false;
  };

  std::optional<Position> PositionOf(const Expr* e) {
    e = e->IgnoreParenImpCasts();
    if (auto* bo = dyn_cast<BinaryOperator>(e); bo && bo->getOpcode() == BO_Add) {
      auto p = PositionOf(bo->getLHS());
      if (!p || p->isEnd) return std::nullopt;
      p->offset = (p->offset.empty() ? "" : p->offset + " + ") + "(" + m_c.Text(bo->getRHS()->getSourceRange()) + ")";
      return p;
    }
    if (auto* op = dyn_cast<CXXOperatorCallExpr>(e); op && op->getOperator() == OO_Plus && op->getNumArgs() == 2) {
      auto p = PositionOf(op->getArg(0));
      if (!p || p->isEnd) return std::nullopt;
      p->offset = (p->offset.empty() ? "" : p->offset + " + ") + "(" + m_c.Text(op->getArg(1)->getSourceRange()) + ")";
      return p;
    }
    if (auto* dr = dyn_cast<DeclRefExpr>(e))
      if (auto* p = dyn_cast<ParmVarDecl>(dr->getDecl()); p && p->getDeclContext() == m_def && p->getType()->isPointerType())
        return Position{"m_inOut_" + m_ctrl.name + "." + p->getNameAsString(), p->getNameAsString(), "", p->getType()->getPointeeType().getUnqualifiedType()};
    if (auto* mc = dyn_cast<CXXMemberCallExpr>(e)) {
      std::string method = mc->getMethodDecl() ? mc->getMethodDecl()->getNameAsString() : "";
      auto* f = ThisField(mc->getImplicitObjectArgument());
      QualType element;
      if (f && IsStdVector(f->getType(), &element) && (method == "begin" || method == "end" || method == "data")) {
        Member* m = FindMember(m_c.model, f->getNameAsString());
        if (!m) return std::nullopt;
        m->usedByKernels = true;  // so that it gets a device buffer
        Position p{"m_vdata." + m->name + ".View()", m->name, "", element.getUnqualifiedType(), m};
        p.isEnd = method == "end";
        return p;
      }
    }
    return std::nullopt;
  }

  std::string ViewAt(const Position& p) {
    if (p.offset.empty()) return p.view;
    return "crossrt::Offset(" + p.view + ", sizeof(" + CppTypeName(m_c.ctx, p.element) + ") * size_t(" + p.offset + "))";
  }

  // Elements from `first` to `last`.
  std::optional<std::string> Count(const Position& first, const Position& last) {
    if (first.key != last.key) return std::nullopt;
    std::string end = last.isEnd ? first.vector->name + ".size()" : last.offset;
    if (end.empty()) end = "0";
    return first.offset.empty() ? "(" + end + ")" : "(" + end + ") - (" + first.offset + ")";
  }

  void WrittenVector(const Position& p) {
    if (p.vector && std::find(m_ctrl.vectorsWritten.begin(), m_ctrl.vectorsWritten.end(), p.vector->name) == m_ctrl.vectorsWritten.end())
      m_ctrl.vectorsWritten.push_back(p.vector->name);
  }

  // How a std::sort call orders its elements, as the GPU radix sort needs it.
  struct SortOrder {
    uint32_t keyWord = 0;
    std::string type;  // "Uint", "Int" or "Float"
    bool descending = false;
  };

  // The crossrt::ElementType of a scan element or sort key: "Uint", "Int", "Float", or "" for others.
  static std::string ElementTypeName(QualType t) {
    const auto* bt = t.getCanonicalType()->getAs<BuiltinType>();
    if (!bt) return "";
    return bt->getKind() == BuiltinType::UInt ? "Uint" : bt->getKind() == BuiltinType::Int ? "Int" : bt->getKind() == BuiltinType::Float ? "Float" : "";
  }

  // `a`, `a.key` or `a.inner.key` with `a` a comparator parameter: which parameter, and the key's
  // byte offset in the element.
  std::optional<std::pair<const ParmVarDecl*, uint64_t>> KeyPath(const Expr* e, std::string& keyType) {
    e = e->IgnoreParenImpCasts();
    uint64_t offset = 0;
    const Expr* base = e;
    keyType = ElementTypeName(e->getType());
    while (auto* me = dyn_cast<MemberExpr>(base)) {
      auto* fd = dyn_cast<FieldDecl>(me->getMemberDecl());
      if (!fd || me->isArrow() || fd->isBitField()) return std::nullopt;
      offset += m_c.ctx.getFieldOffset(fd) / 8;
      base = me->getBase()->IgnoreParenImpCasts();
    }
    auto* dr = dyn_cast<DeclRefExpr>(base);
    auto* parm = dr ? dyn_cast<ParmVarDecl>(dr->getDecl()) : nullptr;
    if (!parm) return std::nullopt;
    return std::make_pair(parm, offset);
  }

  // No comparator, std::less<>/std::greater<>, or a lambda `return a.key < b.key;` (or `>`, or
  // with the parameters swapped) over a uint32_t, int or float key.
  std::optional<SortOrder> OrderOf(const CallExpr* call, QualType element, std::string& why) {
    const std::string scalarType = ElementTypeName(element);
    if (call->getNumArgs() == 2) {
      if (scalarType.empty()) why = "sorting elements without a comparator needs uint32_t, int or float elements";
      return scalarType.empty() ? std::nullopt : std::optional<SortOrder>(SortOrder{0, scalarType, false});
    }
    const Expr* cmp = call->getArg(2)->IgnoreImplicit()->IgnoreParenImpCasts();
    if (auto* mt = dyn_cast<MaterializeTemporaryExpr>(cmp)) cmp = mt->getSubExpr()->IgnoreImplicit();
    if (auto* record = cmp->getType()->getAsCXXRecordDecl(); record && record->isInStdNamespace() &&
                                                          (record->getName() == "less" || record->getName() == "greater")) {
      if (scalarType.empty()) why = "std::less and std::greater sort uint32_t, int or float elements on the GPU";
      return scalarType.empty() ? std::nullopt : std::optional<SortOrder>(SortOrder{0, scalarType, record->getName() == "greater"});
    }
    why = "the GPU sort understands comparators of the form `[](T a, T b) { return a.key < b.key; }` (or `>`) with a "
          "uint32_t, int or float key";
    auto* lambda = dyn_cast<LambdaExpr>(cmp);
    if (!lambda) return std::nullopt;
    auto* op = lambda->getCallOperator();
    auto* body = dyn_cast_or_null<CompoundStmt>(op->getBody());
    if (!body || body->size() != 1 || op->getNumParams() != 2) return std::nullopt;
    auto* ret = dyn_cast<ReturnStmt>(body->body_front());
    auto* cmpOp = ret && ret->getRetValue() ? dyn_cast<BinaryOperator>(ret->getRetValue()->IgnoreParenImpCasts()) : nullptr;
    if (!cmpOp || (cmpOp->getOpcode() != BO_LT && cmpOp->getOpcode() != BO_GT)) return std::nullopt;
    std::string lType, rType;
    auto l = KeyPath(cmpOp->getLHS(), lType), r = KeyPath(cmpOp->getRHS(), rType);
    if (!l || !r || l->second != r->second || l->first == r->first) return std::nullopt;
    if (lType.empty() || lType != rType) return std::nullopt;
    // Both parameters must be the element type (by value or const reference).
    for (auto* parm : op->parameters())
      if (!m_c.ctx.hasSameUnqualifiedType(parm->getType().getNonReferenceType(), element)) return std::nullopt;
    const uint64_t size = m_c.ctx.getTypeSizeInChars(element).getQuantity();
    if (size % 4 != 0 || l->second % 4 != 0) {
      why = "the GPU sort moves whole 32-bit words: the element's size and the key's offset must be multiples of 4 bytes";
      return std::nullopt;
    }
    const bool firstOnLeft = l->first == op->getParamDecl(0);
    const bool descending = (cmpOp->getOpcode() == BO_GT) == firstOnLeft;
    return SortOrder{uint32_t(l->second / 4), lType, descending};
  }

  // LiteMath's ReduceAddInit(v, n) sizes and zeroes v on the host, as written; its device copy, which
  // kernels' ReduceAdd then add into, is zeroed in order with them.
  bool ReduceAddInit(const CallExpr* call) {
    auto* f = call->getNumArgs() == 2 ? ThisField(call->getArg(0)) : nullptr;
    Member* m = f ? FindMember(m_c.model, f->getNameAsString()) : nullptr;
    if (!m || m->kind != MemberKind::Vector) {
      m_c.rep.GpuError(call->getBeginLoc(), "ReduceAddInit of something other than a std::vector member", "pass the member vector kernels add into");
      return true;
    }
    SourceLocation end = Lexer::findLocationAfterToken(call->getEndLoc(), tok::semi, m_c.ctx.getSourceManager(), m_c.ctx.getLangOpts(), false);
    if (end.isInvalid()) {
      m_c.rep.GpuError(call->getBeginLoc(), "ReduceAddInit used inside an expression in control function '" + m_ctrl.name + "'",
                       "call it as a statement of its own: ReduceAddInit(" + m->name + ", n);");
      return true;
    }
    m->usedByKernels = true;
    WrittenVector({"", m->name, "", {}, m});
    m_gpu.InsertTextAfter(end, "\ncrossrt::ZeroCmd(a_cmd, m_vdata." + m->name + ", sizeof(" + m->elemCppType + ") * " + m->name + ".size(), \"" +
                               m_c.cls->getNameAsString() + "::" + m->name + "\");  // its device copy starts at zero too\n");
    return true;
  }

  // std::plus<T>(), std::plus<>() or a lambda `[](T a, T b) { return a + b; }`: the scans the GPU runs.
  static bool IsAddition(const Expr* op) {
    op = op->IgnoreImplicit()->IgnoreParenImpCasts();
    if (auto* mt = dyn_cast<MaterializeTemporaryExpr>(op)) op = mt->getSubExpr()->IgnoreImplicit();
    if (auto* rd = op->getType()->getAsCXXRecordDecl(); rd && rd->isInStdNamespace() && rd->getName() == "plus") return true;
    auto* lambda = dyn_cast<LambdaExpr>(op);
    if (!lambda || lambda->getCallOperator()->getNumParams() != 2) return false;
    auto* body = dyn_cast_or_null<CompoundStmt>(lambda->getCallOperator()->getBody());
    auto* ret = body && body->size() == 1 ? dyn_cast<ReturnStmt>(body->body_front()) : nullptr;
    auto* sum = ret && ret->getRetValue() ? dyn_cast<BinaryOperator>(ret->getRetValue()->IgnoreParenImpCasts()) : nullptr;
    if (!sum || sum->getOpcode() != BO_Add) return false;
    auto param = [](const Expr* e) {
      auto* dr = dyn_cast<DeclRefExpr>(e->IgnoreParenImpCasts());
      return dr ? dyn_cast<ParmVarDecl>(dr->getDecl()) : nullptr;
    };
    const ParmVarDecl *a = param(sum->getLHS()), *b = param(sum->getRHS());
    return a && b && a != b;
  }

  bool TryLibraryCall(const CallExpr* call) {
    auto* fd = call->getDirectCallee();
    if (!fd) return false;
    std::string name = fd->getNameAsString();
    if (name == "ReduceAddInit" && InLiteMath(fd)) return ReduceAddInit(call);
    bool inStd = fd->isInStdNamespace() || IsSystemDecl(fd);
    if (!inStd) return false;
    auto bad = [&](const std::string& why) {
      m_c.rep.GpuError(call->getBeginLoc(), "'" + fd->getQualifiedNameAsString() + "' on device data: " + why,
                    "use member std::vector begin()/end()/data() or size-annotated pointer parameters, with + offsets");
      return true;
    };
    std::string replacement;
    const unsigned nargs = call->getNumArgs();
    if ((name == "exclusive_scan" && (nargs == 4 || nargs == 5)) || (name == "inclusive_scan" && nargs >= 3 && nargs <= 5)) {
      // exclusive_scan(first, last, out, init[, op]); inclusive_scan(first, last, out[, op[, init]]).
      const Expr* op = name == "exclusive_scan" ? (nargs == 5 ? call->getArg(4) : nullptr) : (nargs >= 4 ? call->getArg(3) : nullptr);
      const Expr* initArg = name == "exclusive_scan" ? call->getArg(3) : (nargs == 5 ? call->getArg(4) : nullptr);
      if (op && !IsAddition(op)) return bad("scans on the GPU add: the operation must be std::plus or a lambda returning a + b");
      auto first = PositionOf(call->getArg(0)), last = PositionOf(call->getArg(1)), out = PositionOf(call->getArg(2));
      if (!first || !last || !out) return bad("its ranges are not device buffers the translator can name");
      auto count = Count(*first, *last);
      if (!count) return bad("first and last must belong to the same buffer");
      const std::string type = ElementTypeName(first->element);
      if (type.empty()) return bad("scans on the GPU take uint32_t, int or float elements");
      std::string elem = CppTypeName(m_c.ctx, first->element);
      std::string init = initArg ? "crossrt::Bits32(static_cast<" + elem + ">(" + m_c.Text(initArg->getSourceRange()) + "))" : "0u";
      replacement = "m_scanner.RecordCmd(a_cmd, " + ViewAt(*first) + ", " + ViewAt(*out) + ", uint32_t" + *count + ", " +
                    (name == "inclusive_scan" ? "true" : "false") + ", crossrt::ElementType::" + type + ", " + init + ")";
      WrittenVector(*out);
    } else if (name == "sort" && (call->getNumArgs() == 2 || call->getNumArgs() == 3)) {
      auto first = PositionOf(call->getArg(0)), last = PositionOf(call->getArg(1));
      if (!first || !last) return bad("its range is not a device buffer the translator can name");
      auto count = Count(*first, *last);
      if (!count) return bad("first and last must belong to the same buffer");
      std::string why;
      auto order = OrderOf(call, first->element, why);
      if (!order) return bad(why);
      const uint64_t words = m_c.ctx.getTypeSizeInChars(first->element).getQuantity() / 4;
      const std::string key = "crossrt::SortKey{" + std::to_string(words) + ", " + std::to_string(order->keyWord) +
                              ", crossrt::ElementType::" + order->type + ", " + (order->descending ? "true" : "false") + "}";
      replacement = "m_sorter.RecordCmd(a_cmd, " + ViewAt(*first) + ", uint32_t" + *count + ", " + key + ")";
      // A vector that kernels append to has its size on the GPU: the sort reads it there.
      if (first->vector && m_c.appended.count(first->vector->name)) {
        if (!IsWholeVector(call)) return bad("'" + first->vector->name + "' is appended to by kernels, so its size is known only on the GPU: sort all of it, from begin() to end()");
        const std::string v = first->vector->name;
        replacement = "m_sorter.RecordCmd(a_cmd, " + first->view + ", uint32_t(m_vdata." + v + "Capacity), " + key +
                      ", m_classDataBuffer.View(), offsetof(ClassData, " + v + "_size))";
      }
      // The CPU backend sorts on all cores too, with the same radix sort.
      m_cpu.ReplaceText(call->getSourceRange(), "crossrt::RadixSort(" + m_c.Text(call->getArg(0)->getSourceRange()) + ", " +
                                                    m_c.Text(call->getArg(1)->getSourceRange()) + ", " + key + ")");
      WrittenVector(*first);
    } else if ((name == "memcpy" || name == "memmove") && call->getNumArgs() == 3) {
      auto dst = PositionOf(call->getArg(0)), src = PositionOf(call->getArg(1));
      if (!dst || !src || dst->isEnd || src->isEnd) return bad("source and destination must be device buffers");
      replacement = "crossrt::CopyCmd(a_cmd, " + ViewAt(*src) + ", " + ViewAt(*dst) + ", VkDeviceSize(" + m_c.Text(call->getArg(2)->getSourceRange()) + "))";
      WrittenVector(*dst);
    } else if (name == "fill" && call->getNumArgs() == 3) {
      auto first = PositionOf(call->getArg(0)), last = PositionOf(call->getArg(1));
      if (!first || !last) return bad("its range is not a device buffer the translator can name");
      auto count = Count(*first, *last);
      if (!count) return bad("first and last must belong to the same buffer");
      if (m_c.ctx.getTypeSizeInChars(first->element).getQuantity() != 4) return bad("GPU fills take 32-bit elements");
      std::string elem = CppTypeName(m_c.ctx, first->element);
      replacement = "crossrt::FillCmd(a_cmd, " + ViewAt(*first) + ", sizeof(" + elem + ") * VkDeviceSize" + *count +
                    ", crossrt::Bits32(static_cast<" + elem + ">(" + m_c.Text(call->getArg(2)->getSourceRange()) + ")))";
      WrittenVector(*first);
    } else {
      // Any other library call handed pointers or iterators into device data would run on the
      // host copy while the GPU holds the data: silently wrong, so refuse it.
      for (auto* arg : call->arguments()) {
        QualType t = arg->getType();
        bool pointerLike = t->isPointerType() || (t->getAsCXXRecordDecl() && t->getAsCXXRecordDecl()->getName().contains("iterator"));
        if (pointerLike && PositionOf(arg))
          return bad("on device data the GPU runs std::sort, std::exclusive_scan and std::inclusive_scan (adding), std::fill, memcpy and "
                     "LiteMath's ReduceAddInit; this call would run on a stale host copy");
      }
      return false;
    }
    m_gpu.ReplaceText(call->getSourceRange(), replacement);
    return true;
  }

  void Visit(const Stmt* s) {
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
        m_gpu.ReplaceText(call->getSourceRange(), md->getNameAsString() + "Cmd(a_cmd" + Args(call, false) + ")");
        return;
      }
    }
    for (auto* child : s->children()) Visit(child);
  }

  Context& m_c;
  const CXXMethodDecl* m_md;
  const FunctionDecl* m_def;
  Control& m_ctrl;
  Rewriter m_gpu, m_cpu;
  unsigned m_threadLoops = 0;                  // thread loops seen so far (names the megakernels)
  int m_hostLoopDepth = 0;                     // counted loops around the statement of a thread loop being printed
  std::set<const VarDecl*> m_hostLoopVars;     // counters of loops inside thread loops: the same for all threads
};

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

void AnalyzeControl(Context& c, const CXXMethodDecl* md, const FunctionDecl* def) {
  Control ctrl;
  ctrl.name = md->getNameAsString();
  ctrl.sourceFile = BaseName(FileOf(c.ctx, def->getLocation()));
  ctrl.isConst = md->isConst();
  ctrl.isVirtual = md->isVirtual();
  if (!ctrl.isVirtual)
    c.rep.Warning(md->getLocation(), "control function '" + ctrl.name + "' is not virtual: called through a pointer to " + c.cls->getNameAsString() +
                  " (as the factories return it) it runs " + c.cls->getNameAsString() + "::" + ctrl.name + " as written, on one CPU core",
                  "declare it 'virtual' in " + c.cls->getNameAsString() + " so that the generated classes override it; until then only a pointer to the "
                  "generated class (or its " + ctrl.name + "Cmd) runs it translated");
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
      if (cp.sizeExpr.empty())
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

}  // namespace

bool AnalyzeTranslationUnit(ASTContext& ctx, const std::string& className, const std::map<std::string, std::string>& compositions,
                            Reporter& reporter, ClassModel& model) {
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
    // The file each #include line of the main file brought in, by line.
    std::map<unsigned, std::string> included;
    std::vector<std::string> read;  // every file Clang read, for an include that was skipped (#pragma once)
    auto note = [&](const SrcMgr::SLocEntry& entry) {
      if (!entry.isFile()) return;
      if (auto file = entry.getFile().getContentCache().OrigEntry) read.push_back(file->getName().str());
      const SourceLocation from = entry.getFile().getIncludeLoc();
      // The main file, or its copy in the preamble the AST cache loaded (another FileID).
      if (from.isValid() && (sm.getFileID(from) == sm.getMainFileID() || sm.getFilename(from) == sm.getFilename(sm.getLocForStartOfFile(sm.getMainFileID()))))
        if (auto file = entry.getFile().getContentCache().OrigEntry)
          included[sm.getSpellingLineNumber(from)] = file->getName().str();
    };
    for (unsigned i = 0; i < sm.local_sloc_entry_size(); ++i) note(sm.getLocalSLocEntry(i));
    for (unsigned i = 0; i < sm.loaded_sloc_entry_size(); ++i) note(sm.getLoadedSLocEntry(i));  // the preamble's
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
        if (!llvm::sys::fs::exists(path) && included.count(lineNumber)) path = included[lineNumber];  // found through an include directory
        else if (!llvm::sys::fs::exists(path))  // read before, through another include: the file of that name
          for (auto& name : read)
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

// ---- composition -----------------------------------------------------------

namespace {

// The definition of `name` an implementation provides (itself or a base that is not abstract there).
const CXXMethodDecl* ImplementationOf(const CXXRecordDecl* impl, const std::string& name, const FunctionDecl*& def) {
  for (auto* d : impl->lookup(&impl->getASTContext().Idents.get(name)))
    if (auto* md = dyn_cast<CXXMethodDecl>(d); md && !md->isPureVirtual() && md->hasBody(def) && def) return md;
  for (auto& base : impl->bases())
    if (auto* rd = base.getType()->getAsCXXRecordDecl(); rd && rd->hasDefinition())
      if (auto* md = ImplementationOf(rd->getDefinition(), name, def)) return md;
  return nullptr;
}

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

// ---- virtual functions, level 3, in composed code: intersection shaders (paper 3.10) ----

// Where a leaf call sits: the function whose body holds it, and the statement of that body that
// holds it (the leaves' loop).
struct LeafSite {
  const FunctionDecl* fn = nullptr;
  const clang::Stmt* loop = nullptr;
};

LeafSite FindLeafSite(ASTContext& ctx, const clang::Stmt* call) {
  const clang::Stmt *child = call, *below = nullptr;
  DynTypedNode node = DynTypedNode::create(*call);
  for (;;) {
    auto parents = ctx.getParents(node);
    if (parents.empty()) return {};
    node = parents[0];
    if (auto* fn = node.get<FunctionDecl>()) return fn->getBody() == child && below ? LeafSite{fn, below} : LeafSite{};
    const clang::Stmt* s = node.get<clang::Stmt>();
    if (!s) return {};
    below = child;
    child = s;
  }
}

// The variable of a loop over all leaves, `for (T i = 0; i < count; ++i) [if (test)] call;` (braces
// allowed around one statement), or null when the loop has another shape.
const VarDecl* LeafLoopVariable(const clang::Stmt* loop, const CXXMemberCallExpr* call) {
  auto* fs = dyn_cast<ForStmt>(loop);
  auto* ds = fs ? dyn_cast_or_null<DeclStmt>(fs->getInit()) : nullptr;
  auto* var = ds && ds->isSingleDecl() ? dyn_cast<VarDecl>(ds->getSingleDecl()) : nullptr;
  if (!var || !var->getInit() || !var->getType()->isIntegerType()) return nullptr;
  auto* zero = dyn_cast<IntegerLiteral>(var->getInit()->IgnoreParenImpCasts());
  auto* cond = dyn_cast_or_null<BinaryOperator>(fs->getCond() ? fs->getCond()->IgnoreImplicit() : nullptr);
  auto* inc = dyn_cast_or_null<UnaryOperator>(fs->getInc() ? fs->getInc()->IgnoreImplicit() : nullptr);
  if (!zero || zero->getValue() != 0 || !cond || cond->getOpcode() != BO_LT || NamedVar(cond->getLHS()) != var || !inc || !inc->isIncrementOp() ||
      NamedVar(inc->getSubExpr()) != var)
    return nullptr;
  auto single = [](const clang::Stmt* st) {
    while (auto* cs = dyn_cast_or_null<CompoundStmt>(st)) {
      if (cs->size() != 1) return static_cast<const clang::Stmt*>(nullptr);
      st = cs->body_front();
    }
    return st;
  };
  const clang::Stmt* body = single(fs->getBody());
  if (auto* test = dyn_cast_or_null<IfStmt>(body); test && !test->getElse() && !test->getInit() && !test->getConditionVariable()) body = single(test->getThen());
  auto* expr = dyn_cast_or_null<clang::Expr>(body);
  return expr && expr->IgnoreImplicit() == call ? var : nullptr;
}

// What the leaves' loop does besides the leaf call that the hardware's trace would not: writes to
// variables declared before it (in its test, the only other code LeafLoopVariable lets it have).
// The first such place and why, or "".
struct LoopEffects : WriteVisitor<LoopEffects> {
  const CXXMemberCallExpr* leafCall;
  std::set<const VarDecl*> inner;  // declared inside the loop
  std::string problem;
  SourceLocation where;

  explicit LoopEffects(const CXXMemberCallExpr* call) : leafCall(call) {}
  void Note(SourceLocation loc, const std::string& what) {
    if (problem.empty()) { problem = what; where = loc; }
  }
  void Written(const clang::Expr* target, SourceLocation loc) {
    const VarDecl* vd = WrittenVar(target);
    if (vd && !inner.count(vd)) Note(loc, "it writes '" + vd->getNameAsString() + "', declared before the loop");
  }
  bool VisitVarDecl(VarDecl* vd) { inner.insert(vd); return true; }
  // Besides WriteVisitor's: non-const methods and non-const reference arguments.
  bool VisitCallExpr(CallExpr* call) {
    if (call == leafCall) return true;
    if (auto* mc = dyn_cast<CXXMemberCallExpr>(call); mc && mc->getMethodDecl() && !mc->getMethodDecl()->isConst())
      Written(mc->getImplicitObjectArgument(), mc->getExprLoc());  // a non-const method changes its object
    const FunctionDecl* fd = call->getDirectCallee();
    const unsigned shift = isa<CXXOperatorCallExpr>(call) && isa_and_nonnull<CXXMethodDecl>(fd) ? 1 : 0;  // argument 0 is the object
    for (unsigned i = 0; fd && i + shift < call->getNumArgs() && i < fd->getNumParams(); ++i) {
      QualType pt = fd->getParamDecl(i)->getType();
      if (pt->isReferenceType() && !pt.getNonReferenceType().isConstQualified()) Written(call->getArg(i + shift), call->getArg(i + shift)->getExprLoc());
    }
    return true;
  }
};

// GLSL zero of a hit struct's field type (scalars, vectors and arrays of them), or "".
std::string ZeroOf(QualType t) {
  t = t.getCanonicalType();
  if (auto* arr = dyn_cast<ConstantArrayType>(t.getTypePtr())) {
    const std::string element = ZeroOf(arr->getElementType());
    auto g = GlslTypeOf(arr->getElementType());
    if (element.empty() || !g) return "";
    std::string out = *g + "[" + std::to_string(arr->getSize().getZExtValue()) + "](";
    for (uint64_t i = 0; i < arr->getSize().getZExtValue(); ++i) out += (i ? ", " : "") + element;
    return out + ")";
  }
  if (t->isRecordType() && !IsLiteMathType(t)) return "";
  auto g = GlslTypeOf(t);
  return g ? *g + "(0)" : "";
}

// The interface method that gives a leaf's box corner on the host: public `name() const`, no
// parameters, returning a LiteMath float3 or float4, declared by the interface or a public base of
// it. Else null.
const CXXMethodDecl* BoxCorner(const CXXRecordDecl* interface, const std::string& name) {
  auto found = interface->lookup(&interface->getASTContext().Idents.get(name));
  for (auto* d : found)
    if (auto* md = dyn_cast<CXXMethodDecl>(d); md && md->isConst() && md->getNumParams() == 0 && md->getAccess() == AS_public) {
      auto g = GlslTypeOf(md->getReturnType().getNonReferenceType().getUnqualifiedType());
      if (g && (*g == "vec3" || *g == "vec4")) return md;
    }
  if (!found.empty()) return nullptr;  // the interface's own declarations hide its bases'
  for (auto& base : interface->bases())
    if (auto* rd = base.getType()->getAsCXXRecordDecl(); rd && rd->hasDefinition() && base.getAccessSpecifier() == AS_public)
      if (auto* md = BoxCorner(rd->getDefinition(), name)) return md;
  return nullptr;
}

// One leaf call of a composed traversal (listing 2 of the paper):
//   for (...) if (<box test>) m_shapes[i]->Intersect(posAndNear, dirAndFar, i, hit);
// The ray tracing hardware can run its loop when the call has the fixed form the paper gives
// Intersect: the ray (two float4: origin and near, direction and far) first, the hit last (a struct
// whose first field is its distance, updated when the leaf is nearer), and between them only the
// leaf's index or constants. Then `hardware` prints a trace where the loop was; the call's site
// (its vector and method, shared by other calls of both) joins `sites`, and its intersection,
// closest-hit and miss shaders join `shaders`. Returns why not, or "".
std::string TraceLeafCall(ASTContext& ctx, Reporter& rep, const ClassModel& model, const Composition& comp, const CXXRecordDecl* implClass,
                          const CXXMemberCallExpr* call, GlslPrinter& hardware, std::vector<LeafTraversal>& sites, std::vector<std::string>& payloads,
                          std::vector<StageShader>& shaders) {
  SourceManager& sm = ctx.getSourceManager();
  auto at = [&](SourceLocation loc) {
    PresumedLoc p = sm.getPresumedLoc(sm.getFileLoc(loc));
    return p.isValid() ? BaseName(p.getFilename()) + ":" + std::to_string(p.getLine()) : std::string("?");
  };
  const clang::Expr* indexExpr = nullptr;
  const FieldDecl* field = VirtualCallTarget(call, &indexExpr);
  const CXXMethodDecl* method = call->getMethodDecl();
  const std::string member = hardware.composedPrefix + field->getNameAsString(), site = at(call->getBeginLoc());
  auto vm = std::find_if(model.virtuals.begin(), model.virtuals.end(), [&](const VirtualMember& v) { return v.member == member; });
  if (vm == model.virtuals.end() || vm->impls.empty()) return "no class that implements it can be copied to the GPU";  // reported
  const std::string callText = vm->display + "[...]->" + method->getNameAsString();
  const LeafSite leaf = FindLeafSite(ctx, call);
  if (!leaf.fn || !isa<ForStmt, WhileStmt, DoStmt, CXXForRangeStmt>(leaf.loop))
    return "the leaf call " + callText + " (" + site + ") is not inside a loop of the traversal's body";
  // The trace visits every leaf once: the loop must say so, `for (T i = 0; i < count; ++i)` whose
  // body is the call, perhaps behind a test (the leaf's box test, which the hardware does instead).
  const VarDecl* loopVar = LeafLoopVariable(leaf.loop, call);
  if (!loopVar)
    return "the loop calling " + callText + " (" + site + ") is not 'for (i = 0; i < count; ++i) [if (box test)] " + method->getNameAsString() +
           "(...);', which visits every leaf once as the hardware does";
  LoopEffects effects(call);
  effects.TraverseStmt(const_cast<clang::Stmt*>(leaf.loop));
  if (!effects.problem.empty()) return "the loop calling " + callText + " does more than visit leaves: " + effects.problem + " (" + at(effects.where) + ")";

  // The call's form: (float4 ray origin and near, float4 direction and far, leaf index or constants..., Hit& hit).
  const unsigned n = method->getNumParams();
  auto isFloat4 = [](QualType t) { return GlslTypeOf(t.getNonReferenceType().getUnqualifiedType()).value_or("") == "vec4"; };
  const QualType hitParam = n ? method->getParamDecl(n - 1)->getType() : QualType();
  const auto* hitRecord = n ? hitParam.getNonReferenceType()->getAsCXXRecordDecl() : nullptr;
  const std::string form = "(float4 posAndNear, float4 dirAndFar, [leaf index or constants,] Hit& hit)";
  if (n < 3 || !isFloat4(method->getParamDecl(0)->getType()) || !isFloat4(method->getParamDecl(1)->getType()) || !WrittenBack(method, n - 1) ||
      !hitRecord || hitRecord->isPolymorphic() || !method->getReturnType()->isVoidType())
    return callText + " does not have the form of an intersection function, void " + method->getNameAsString() + form;
  const FieldDecl* distance = hitRecord->field_empty() ? nullptr : *hitRecord->field_begin();
  if (!distance || !distance->getType()->isSpecificBuiltinType(BuiltinType::Float))
    return "the hit " + hitRecord->getNameAsString() + " does not start with its distance (a float)";
  const uint64_t hitBytes = ctx.getTypeSize(hitParam.getNonReferenceType()) / 8;
  if (hitBytes > 32)
    return "the hit " + hitRecord->getNameAsString() + " takes " + std::to_string(hitBytes) +
           " bytes; intersection shaders report at most 32 (Vulkan's guaranteed hit attribute size)";
  std::string zeroHit;
  for (auto* f : hitRecord->fields()) {
    if (f == distance) continue;  // the ray's end, set after
    const std::string zero = ZeroOf(f->getType());
    if (zero.empty()) return "the hit " + hitRecord->getNameAsString() + " has a field, '" + f->getNameAsString() + "', that is not a scalar, vector or array of them";
    zeroHit += "  hit." + GlslPrinter::SafeName(f->getNameAsString()) + " = " + zero + ";\n";
  }
  // Arguments: the ray and the hit as the traversal has them before the loop; the index as the leaf.
  if (NamedVar(indexExpr) != loopVar)
    return callText + " picks its object with an expression, not the loop's variable: the hardware names a leaf by its element's position";
  auto outer = [&](const clang::Expr* e) {
    const VarDecl* vd = NamedVar(e);
    return vd && vd->isLocalVarDeclOrParm() && !effects.inner.count(vd) ? vd : nullptr;
  };
  if (!outer(call->getArg(0)) || !outer(call->getArg(1)) || !outer(call->getArg(n - 1)))
    return "the ray and the hit " + callText + " takes must be variables of the traversal declared before the loop";
  // In the intersection shader, the leaf's index is its instance's: one instance per element, in order.
  GlslPrinter literals(ctx, implClass, rep);
  std::vector<std::string> leafArgs;
  for (unsigned i = 2; i + 1 < n; ++i) {
    const clang::Expr* arg = call->getArg(i)->IgnoreParenImpCasts();
    auto type = GlslTypeOf(method->getParamDecl(i)->getType().getNonReferenceType().getUnqualifiedType());
    if (NamedVar(arg) == loopVar && type) leafArgs.push_back(*type + "(gl_InstanceID)");
    else if (isa<IntegerLiteral, FloatingLiteral, CXXBoolLiteralExpr>(arg) && type) leafArgs.push_back(*type + "(" + literals.Expr(arg) + ")");
    else return "argument " + std::to_string(i + 1) + " of " + callText + " is neither the leaf's index nor a constant";
  }
  QualType element;
  IsStdVector(field->getType(), &element);
  const CXXRecordDecl* interface = PolymorphicPointee(element);  // the elements' (the method may be a base's)
  const CXXMethodDecl *boxMin = BoxCorner(interface, "BoxMin"), *boxMax = BoxCorner(interface, "BoxMax");
  if (!boxMin || !boxMax)
    return interface->getNameAsString() + " declares no public BoxMin() const and BoxMax() const (float3 or float4), nor inherits them: the hardware needs each leaf's box";

  // The site: a vector and a method. Its traces start their hit groups after the earlier sites' (the
  // SBT record offset, of which traceRayEXT uses 4 bits) and have its miss shader and payload.
  const std::string methodName = method->getNameAsString();
  auto known = std::find_if(sites.begin(), sites.end(), [&](const LeafTraversal& s) { return s.member == member && s.method == methodName; });
  const bool fresh = known == sites.end();
  LeafTraversal lt;
  if (fresh) {
    lt.member = member;
    lt.hostExpr = vm->hostExpr;
    lt.display = vm->display;
    lt.interfaceName = interface->getNameAsString();
    lt.method = methodName;
    lt.traversal = comp.implName + "::" + leaf.fn->getNameAsString();
    lt.missIndex = unsigned(sites.size());
    for (auto& s : sites) lt.firstHitGroup += unsigned(s.intersectionShaders.size());
    if (lt.firstHitGroup > 15)
      return "the leaf calls before " + callText + " (" + site + ") have " + std::to_string(lt.firstHitGroup) +
             " classes; a trace can skip at most 15 hit groups (traceRayEXT's SBT record offset has 4 bits)";
  } else {
    lt = *known;
  }
  const std::string payload = member + "_" + methodName + "_hit", scene = member + "_leaves";
  const std::string p = hardware.Expr(call->getArg(0)), d = hardware.Expr(call->getArg(1)), h = hardware.Expr(call->getArg(n - 1));
  const std::string t = h + "." + GlslPrinter::SafeName(distance->getNameAsString()), number = std::to_string(lt.missIndex);
  std::ostringstream trace;
  trace << "// The loop of " << comp.implName << "::" << leaf.fn->getNameAsString() << " calling " << callText << " (" << site << ")\n"
        << "// runs on the ray tracing hardware: it finds the leaves whose boxes the ray meets, and the\n"
        << "// intersection shader of each leaf's class calls its " << methodName << " (virtual functions, level 3).\n"
        << "{\n  const float crt_near = max(" << p << ".w, 0.0);  // rays start at a distance >= 0 on the hardware\n"
        << "  const bool crt_finite = !any(isnan(" << p << ")) && !any(isinf(" << p << ".xyz)) && !any(isnan(" << d << ".xyz)) && !any(isinf(" << d << ".xyz));\n"
        << "  " << payload << " = " << h << ";\n"
        << "  // The leaf's hit group is " << (lt.firstHitGroup ? std::to_string(lt.firstHitGroup) + " + " : std::string()) << "its class; miss shader and payload " << number << ".\n"
        << "  if (crt_finite && crt_near < " << t << ")\n"
        << "    traceRayEXT(" << scene << ", gl_RayFlagsNoneEXT, 0xFF, " << lt.firstHitGroup << ", 0, " << number << ", " << p << ".xyz, crt_near, " << d
        << ".xyz, " << t << ", " << number << ");\n"
        << "  " << h << " = " << payload << ";\n}\n";
  hardware.replacedStatements[leaf.loop] = trace.str();
  const std::string hitType = *hardware.Type(hitParam.getNonReferenceType().getUnqualifiedType(), call->getBeginLoc());
  if (fresh)
    payloads.push_back("// The hit the leaves' intersection shaders report to (" + callText + "'s last argument)\nlayout(location = " + number +
                       ") rayPayloadEXT " + hitType + " " + payload + ";\n");

  // A shader per name: another call (of this kernel or another) may already have it, from the same code.
  auto addShader = [&](const StageShader& s) {
    using Shaders = const std::vector<StageShader>*;
    for (Shaders list : {Shaders(&model.leafShaders), Shaders(&shaders)})
      for (const StageShader& x : *list)
        if (x.name == s.name) return x.mainBody == s.mainBody;
    shaders.push_back(s);
    return true;
  };
  // Per class, an intersection shader: the leaf's object, its method on the hardware's ray, and the
  // hit reported when it is nearer than the nearest so far (the ray's end).
  std::vector<const CXXRecordDecl*> impls;
  FindImplementations(ctx.getTranslationUnitDecl(), interface, impls);
  lt.intersectionShaders.clear();
  for (const VirtualImpl& vi : vm->impls) {
    auto impl = std::find_if(impls.begin(), impls.end(), [&](const CXXRecordDecl* r) { return r->getNameAsString() == vi.name; });
    if (impl == impls.end()) return vi.name + " is not defined where the traversal is";
    const std::string name = member + "_" + vi.name + "_" + methodName;
    lt.intersectionShaders.push_back(name);
    GlslPrinter object(ctx, *impl, rep);
    object.selfClass = *impl;
    object.composedPrefix = vi.name + "_";
    for (auto& sn : ClassStructNames(model)) object.predeclaredStructs.insert(sn);
    const std::string function = ImplementationMethod(rep, object, *impl, method, call->getBeginLoc());
    if (function.empty()) return "the GPU has no body of " + vi.name + "::" + methodName;  // reported
    object.Type(hitParam.getNonReferenceType().getUnqualifiedType(), call->getBeginLoc());
    StageShader s;
    s.name = name;
    s.stage = "rint";
    s.origin = vi.name + "::" + methodName;
    s.description = "what " + callText + " runs for a leaf that is a " + vi.name + ",\n// as the intersection shader of the ray tracing pipelines tracing " +
                    vm->display + "'s leaves (virtual functions, level 3)";
    s.scalarLayout = vi.scalarLayout;
    s.classData = true;
    for (auto& x : object.Constants()) s.constants += x;
    for (auto& x : object.Structs()) s.structs += x + "\n";
    s.structs += TagsReference(model, *vm) + "\n" + ImplDataStruct(object, *impl, *vm, vi) + "\n" + ObjectsReference(*vm, vi) + "\n" +
                 "hitAttributeEXT " + hitType + " crt_hit;  // what the closest-hit shader receives\n";
    for (auto& x : object.Functions()) s.functions += x + "\n";
    std::string args = "self, vec4(gl_WorldRayOriginEXT, gl_RayTminEXT), vec4(gl_WorldRayDirectionEXT, gl_RayTmaxEXT)";
    for (auto& a : leafArgs) args += ", " + a;
    const std::string dist = GlslPrinter::SafeName(distance->getNameAsString());
    s.mainBody = "  // The leaf is element gl_InstanceID of " + vm->display + " (one instance per element, in order).\n"
                 "  const uvec2 tag = " + member + "_Tags(" + member + "_tags).tags[gl_InstanceID];\n"
                 "  const " + vi.name + "_Data self = " + member + "_" + vi.name + "Objects(" + member + "_" + vi.name + ").objects[tag.y];\n"
                 "  // Nearer than the ray's end (the nearest hit so far) or nothing: the other fields start at zero.\n"
                 "  " + hitType + " hit;\n" + zeroHit + "  hit." + dist + " = gl_RayTmaxEXT;\n"
                 "  " + function + "(" + args + ", hit);\n"
                 "  if (hit." + dist + " < gl_RayTmaxEXT)\n  {\n    crt_hit = hit;\n"
                 "    reportIntersectionEXT(hit." + dist + ", 0u);\n  }\n";
    if (!addShader(s)) return "another leaf call of " + callText + " passes other arguments (" + site + ")";
  }
  // The closest-hit shader hands the nearest leaf's hit to the trace; the miss shader leaves it.
  lt.closestHitShader = member + "_" + methodName + "_Hit";
  lt.missShader = member + "_" + methodName + "_Miss";
  std::string hitStructs;
  for (auto& x : hardware.Structs()) hitStructs += x + "\n";
  StageShader chit;
  chit.name = lt.closestHitShader;
  chit.stage = "rchit";
  chit.origin = callText;
  chit.description = "the nearest leaf's hit, handed to the trace of " + vm->display + "'s leaves (virtual functions, level 3)";
  chit.structs = hitStructs + "hitAttributeEXT " + hitType + " crt_hit;  // from the leaf's intersection shader\n" +
                 "layout(location = 0) rayPayloadInEXT " + hitType + " hit;\n";
  chit.mainBody = "  hit = crt_hit;\n";
  addShader(chit);
  StageShader miss;
  miss.name = lt.missShader;
  miss.stage = "rmiss";
  miss.origin = callText;
  miss.description = "a ray that meets none of " + vm->display + "'s leaves keeps the hit it had (virtual functions, level 3)";
  addShader(miss);
  if (fresh) sites.push_back(lt);
  return "";
}

// Virtual functions, level 3, in composed code. When every virtual call of the composed traversal
// `printer` printed for kernel `k` is a leaf call the hardware can run (TraceLeafCall), the kernel
// gets a ray generation variant whose traversal traces a ray where each leaves' loop was, with an
// intersection shader per class of leaf. Otherwise the reason goes to k.whyNoLeafShaders and the
// kernel keeps the switch.
void AnalyzeLeafTraversal(ASTContext& ctx, Reporter& rep, ClassModel& model, Kernel& k, const Composition& comp, const CXXRecordDecl* implClass,
                          const std::string& holderPrefix, const GlslPrinter& printer) {
  if (std::any_of(k.composedCalls.begin(), k.composedCalls.end(), [&](const auto& c) { return c.first != comp.holder; })) {
    k.whyNoLeafShaders = "it calls code composed through more than one member";
    return;
  }
  // The traversal again, with each leaves' loop replaced by a trace (the leaves' code is left out).
  GlslPrinter hardware(ctx, implClass, rep);
  hardware.composedPrefix = holderPrefix;
  for (auto& sn : ClassStructNames(model)) hardware.predeclaredStructs.insert(sn);
  std::vector<LeafTraversal> sites;
  std::vector<std::string> payloads;
  std::vector<StageShader> shaders;
  for (const CXXMemberCallExpr* call : printer.virtualCallSites)
    if (std::string why = TraceLeafCall(ctx, rep, model, comp, implClass, call, hardware, sites, payloads, shaders); !why.empty()) {
      k.whyNoLeafShaders = why;
      return;
    }
  for (auto& [holder, name] : k.composedCalls) {
    const FunctionDecl* def = nullptr;
    if (auto* md = ImplementationOf(implClass, name, def)) hardware.EmitComposedMethod(md);
  }
  // Structs: the kernel's (composition merged them in) and the payloads; functions: the traversal's
  // without the leaves' code, then the kernel's own.
  k.leafStructList = k.structList;
  for (auto& x : hardware.Structs())
    if (std::find(k.leafStructList.begin(), k.leafStructList.end(), x) == k.leafStructList.end()) k.leafStructList.push_back(x);
  k.leafStructList.insert(k.leafStructList.end(), payloads.begin(), payloads.end());
  k.leafFunctionList = hardware.Functions();
  for (auto& x : k.ownFunctionList)
    if (std::find(k.leafFunctionList.begin(), k.leafFunctionList.end(), x) == k.leafFunctionList.end()) k.leafFunctionList.push_back(x);
  model.leafShaders.insert(model.leafShaders.end(), shaders.begin(), shaders.end());
  k.leaves = sites;
}

std::string StructName(const std::string& chunk) {
  static const std::regex decl(R"(^struct (\w+) \{)");
  std::smatch m;
  return std::regex_search(chunk, m, decl) ? m[1].str() : "";
}

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
      GlslPrinter printer(ctx, impl, reporter);
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
      std::vector<std::string> virtualStructs, virtualFunctions;
      if (!printer.virtualCalls.empty())
        VirtualCallCode(ctx, reporter, model, k, printer, VirtualOwner{impl, holderPrefix, "crt_" + comp.holder + "()->", comp.holder}, virtualStructs,
                        virtualFunctions);
      CheckObjectSizeReads(reporter, printer);
      for (auto* fn : printer.helpers) {
        ComposedWriteFinder finder;
        finder.TraverseStmt(fn->getBody());
        for (auto& [field, loc] : finder.writes)
          reporter.GpuError(loc, "composed code writes member '" + field->getNameAsString() + "' of " + comp.implName +
                         ", whose GPU copy is never read back", "members of a composed implementation are read-only in kernels: compute into a local variable");
      }
      // The implementation's data: its std::vector members become buffers, plain members join
      // the class data, all reached through the holder on the host.
      std::vector<std::string> vectors;
      for (auto* f : printer.memberVectors) {
        QualType elem;
        IsStdVector(f->getType(), &elem);
        printer.Type(elem, f->getLocation());
      }
      auto requirePublic = [&](const FieldDecl* f) {
        RequirePublicForComposition(reporter, f, comp.implName, " (" + comp.interfaceName + "=" + comp.implName + ")");
      };
      for (auto* f : printer.memberVectors) {
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
      for (auto* f : printer.plainMembers) {
        requirePublic(f);
        std::string name = holderPrefix + f->getNameAsString();
        if (FindMember(model, name)) continue;
        Member m;
        m.name = name;
        m.hostExpr = "crt_" + comp.holder + "()->" + f->getNameAsString();
        m.glslType = GlslTypeOf(f->getType()).value_or("float");
        m.cppType = CppTypeName(ctx, f->getType());
        m.inClassData = FitsClassData(ctx, f->getType());
        if (auto layout = Std430Layout(ctx, f->getType(), false)) m.std430Align = unsigned(layout->align);
        if (!m.inClassData)
          reporter.GpuError(f->getLocation(), "member '" + f->getNameAsString() + "' of type '" + f->getType().getAsString(ctx.getPrintingPolicy()) +
                         "' has a C++ layout that a GPU buffer cannot reproduce",
                         "use int instead of bool, float4x4 instead of float3x3");
        m.usedByKernels = true;
        model.members.push_back(m);
      }
      // Composed code first: the kernel's own code calls it and may use its structs.
      std::vector<std::string> structs = printer.Structs(), constants = printer.Constants(), functions;
      std::vector<std::string> own = printer.Functions();
      for (auto* list : {&virtualFunctions, &own})  // free functions several print are the same text: once
        for (auto& x : *list)
          if (std::find(functions.begin(), functions.end(), x) == functions.end()) functions.push_back(x);
      for (auto* list : {&virtualStructs, &k.structList})
        for (auto& chunk : *list) {
          auto same = std::find_if(structs.begin(), structs.end(), [&](const std::string& x) {
            return StructName(x) == StructName(chunk) && (!StructName(x).empty() || x == chunk);
          });
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
      if (comp.interfaceName == "ISceneObject" && onlyRayQueries && printer.virtualCalls.empty()) k.rayQueryHolder = comp.holder;
      // Virtual intersection functions called per leaf can run as intersection shaders (level 3).
      if (model.virtualLevel == 3 && !printer.virtualCalls.empty() && reporter.Errors() == 0)
        AnalyzeLeafTraversal(ctx, reporter, model, k, comp, impl, holderPrefix, printer);
    }
  }
  return any;
}

// A megakernel runs its kernels' thread functions: it needs their structs, constants, helpers
// (composed code included, so after composition), buffers and images.
static void MergeMegakernelCode(ClassModel& model) {
  for (auto& mk : model.megakernels) {
    std::vector<std::string> functions;
    auto addUnique = [](auto& list, const auto& x) {
      if (std::find(list.begin(), list.end(), x) == list.end()) list.push_back(x);
    };
    for (auto& name : mk.megakernelCalls) {
      auto k = std::find_if(model.kernels.begin(), model.kernels.end(), [&](const Kernel& x) { return x.name == name; });
      if (k == model.kernels.end()) continue;
      for (auto& chunk : k->structList)
        if (std::none_of(mk.structList.begin(), mk.structList.end(), [&](const std::string& x) { return StructName(x) == StructName(chunk); }))
          mk.structList.push_back(chunk);
      for (auto& x : k->constantList) addUnique(mk.constantList, x);
      for (auto& x : k->functionList) addUnique(functions, x);
      addUnique(functions, k->glslBody);
      for (auto& v : k->memberVectors) addUnique(mk.memberVectors, v);
      for (auto& ib : k->images) {
        auto same = std::find_if(mk.images.begin(), mk.images.end(), [&](const ImageBinding& x) { return x.member == ib.member && x.use == ib.use; });
        if (same == mk.images.end()) mk.images.push_back(ib);
        else { same->loaded |= ib.loaded; same->stored |= ib.stored; }
      }
      for (auto& pair : k->samplePairs) addUnique(mk.samplePairs, pair);
      for (auto& array : k->textureArrays) addUnique(mk.textureArrays, array);
      mk.composedCalls.insert(k->composedCalls.begin(), k->composedCalls.end());
      mk.bufferReferences |= k->bufferReferences;
      mk.atomics |= k->atomics;
      mk.scalarReferences |= k->scalarReferences;
    }
    std::sort(mk.memberVectors.begin(), mk.memberVectors.end());
    mk.functionList = functions;
  }
}

void FinishModel(ClassModel& model) {
  MergeMegakernelCode(model);
  // The class-data block: plain members kernels use, then sizes of member vectors.
  // Ordered by alignment so that the C++ mirror with alignas() has the std430 offsets.
  std::vector<BlockField> fields;
  for (auto& m : model.members)
    if (m.kind == MemberKind::Plain && m.inClassData && (m.usedByKernels || m.hostExpr == m.name))
      fields.push_back({m.name, m.cppType, m.glslType, m.std430Align, m.hostExpr, ""});
  for (auto& m : model.members) {
    if (!m.usedByKernels || m.kind != MemberKind::Vector) continue;
    fields.push_back({m.name + "_size", "uint32_t", "uint", 4, "", ""});
    fields.push_back({m.name + "_capacity", "uint32_t", "uint", 4, "", ""});
  }
  for (auto& m : model.members) {
    if (!m.usedByKernels || m.kind != MemberKind::Image) continue;
    fields.push_back({m.name + "_width", "uint32_t", "uint", 4, "", m.hostExpr + ".width()"});
    fields.push_back({m.name + "_height", "uint32_t", "uint", 4, "", m.hostExpr + ".height()"});
  }
  for (auto& m : model.members)
    if (m.usedByKernels && m.kind == MemberKind::TextureArray) fields.push_back({m.name + "_size", "uint32_t", "uint", 4, "", "uint32_t(" + m.hostExpr + ".size())"});
  // Virtual functions: where each vector's tags and each implementation's objects are on the device.
  for (auto& v : model.virtuals) {
    fields.push_back({v.member + "_tags", "uint64_t", "uvec2", 8, "", "m_virtual." + v.member + "_tags.Address()"});
    fields.push_back({v.member + "_size", "uint32_t", "uint", 4, "", "uint32_t(" + v.hostExpr + ".size())"});
    if (model.virtualLevel == 1) fields.push_back({v.member + "_objects", "uint64_t", "uvec2", 8, "", "m_virtual." + v.member + "_objects.Address()"});
    for (auto& impl : v.impls)
      if (model.virtualLevel >= 2)
        fields.push_back({v.member + "_" + impl.name, "uint64_t", "uvec2", 8, "", "m_virtual." + v.member + "_" + impl.name + ".Address()"});
  }
  std::stable_sort(fields.begin(), fields.end(), [](const BlockField& a, const BlockField& b) { return a.std430Align > b.std430Align; });
  if (fields.empty()) fields.push_back({"dummy", "uint32_t", "uint", 4, "", ""});  // a block needs a member
  model.classData = fields;
}

}  // namespace crossrt::engine
