// Questions the passes ask of Clang's AST: source text and files of declarations, the member or
// variable an expression names or writes, a class's fields and methods (bases first), and which
// functions push_back to member vectors. Takes AST nodes, gives answers; changes nothing.
#pragma once
#include "analyse/AnalysisContext.h"
#include "analyse/Naming.h"

namespace crossrt::engine {

// "dir/File.cpp" -> "File.cpp".
std::string BaseName(const std::string& path);

// The source text of `range` as written.
std::string Text(const ASTContext& ctx, SourceRange range);

// The name of the file that holds `loc` (its expansion), as Clang opened it; "" for none.
std::string FileOf(const ASTContext& ctx, SourceLocation loc);

// `loc`'s expansion as file, line and column.
SourcePlace PlaceOf(const ASTContext& ctx, SourceLocation loc);

std::string ParamDecl(const ASTContext& ctx, const ParmVarDecl* p, unsigned index);

// A parameter as the declaration `p` writes its type (valid where the class is declared), named
// as the definition `named` names it (its body uses that name).
std::string ParamDecl(const ASTContext& ctx, const ParmVarDecl* p, const ParmVarDecl* named, unsigned index);

std::string CppTypeName(const ASTContext& ctx, QualType t);

// The member `e` names through `this` (m_x or this->m_x), or null.
const FieldDecl* ThisField(const Expr* e);

// The member a written lvalue belongs to: this->m_v[i].x -> m_v.
const FieldDecl* RootField(const Expr* e);

// The variable an expression names (through parentheses, implicit casts and copies), or null.
const VarDecl* NamedVar(const clang::Expr* e);

// The variable at the root of a written expression: v in v, v.f, v[i], v.f[i].g; else null.
const VarDecl* WrittenVar(const clang::Expr* e);

// The data members kernels may use: the bases' first (in declaration order), then the class's own.
std::vector<const FieldDecl*> ClassFields(const CXXRecordDecl* cls);

// The member functions a translation looks at: the class's own, then those of its bases it does not
// hide by name (a control function or kernel declared in a base, kernel_slicer's inheritance form).
std::vector<const CXXMethodDecl*> ClassMethods(const CXXRecordDecl* cls);

bool InLiteMath(const Decl* d);

// The class or one of its bases: a member function defined there is one of the class's.
bool IsClassOrBase(const CXXRecordDecl* rd, const CXXRecordDecl* cls);

// `m_v.push_back(x)` on a std::vector member of the class: the member, else null.
const FieldDecl* AppendTarget(const CXXMemberCallExpr* call);

// The variable `v` of an argument written `&v`, else null.
const VarDecl* AddressedVar(const Expr* arg);

// The class's own member function a call `this->f(...)` reaches, defined, else null.
const FunctionDecl* ThisMethodDef(const CXXMemberCallExpr* call, const CXXRecordDecl* cls);

// Whether `s` calls a function anywhere inside it.
bool ContainsCall(const Stmt* s);

// Whether `s` names declaration `d` anywhere inside it.
bool Mentions(const Stmt* s, const Decl* d);

// Whether `fn` appends to a member vector, itself or through the class's member functions it calls.
bool AppendsThroughCalls(const FunctionDecl* fn, const CXXRecordDecl* cls, std::map<const FunctionDecl*, bool>& memo);

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

}  // namespace crossrt::engine
