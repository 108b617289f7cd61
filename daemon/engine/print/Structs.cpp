// Plain structs' own code in kernels: member functions, overloaded operators and constructors.
//
// GLSL structs have data only, so each becomes a function that takes the object first:
//   c.norm()          -> complex_norm(c)            `complex self` (inout self for a non-const one)
//   a * b             -> complex_op_mul(a, b)        a member operator; a free one is op_mul(a, b)
//   complex(re, im)   -> complex_ctor(re, im)        a user-provided constructor, which builds `self`
// The struct's members read and write `self`. LiteMath's vectors and matrices are GLSL's own types
// and keep GLSL's operators; their few member functions (get_col, ...) are mapped by name.
#include "analyse/AstQueries.h"
#include "print/KernelPrinter.h"

#include <clang/AST/DeclCXX.h>

#include <sstream>

using namespace clang;

namespace crossrt::engine {

namespace {

// Operator names GLSL accepts in a function name.
std::string OperatorWord(OverloadedOperatorKind k, unsigned params) {
  switch (k) {
    case OO_Plus: return params == 1 ? "plus" : "add";
    case OO_Minus: return params == 1 ? "neg" : "sub";
    case OO_Star: return "mul";
    case OO_Slash: return "div";
    case OO_Percent: return "mod";
    case OO_PlusEqual: return "addAssign";
    case OO_MinusEqual: return "subAssign";
    case OO_StarEqual: return "mulAssign";
    case OO_SlashEqual: return "divAssign";
    case OO_EqualEqual: return "equal";
    case OO_ExclaimEqual: return "notEqual";
    case OO_Less: return "less";
    case OO_Greater: return "greater";
    case OO_LessEqual: return "lessEqual";
    case OO_GreaterEqual: return "greaterEqual";
    case OO_Subscript: return "at";
    case OO_Call: return "call";
    case OO_Exclaim: return "not";
    case OO_Equal: return "assign";
    default: return "op" + std::to_string(int(k));
  }
}

}  // namespace

bool KernelPrinter::IsPlainStruct(const CXXRecordDecl* rd) const {
  if (!rd || !rd->hasDefinition() || rd == m_class || rd->isPolymorphic() || rd->isUnion() || rd->getName().empty()) return false;
  QualType t = m_ctx.getRecordType(rd);
  if (IsLiteMathType(t) || IsStdVector(t) || IsImage2D(t) || IsImageSampler(t) || IsSystemDecl(rd)) return false;
  for (auto* dc = rd->getDeclContext(); dc; dc = dc->getParent())  // LiteImage's images and textures are the GPU's own
    if (auto* ns = dyn_cast<NamespaceDecl>(dc); ns && ns->getName() == "LiteImage") return false;
  // Data the GPU can hold: every field of a GLSL type (the struct is then declared in the shader).
  for (auto* f : rd->fields()) {
    QualType ft = f->getType();
    while (auto* arr = dyn_cast<ConstantArrayType>(ft.getCanonicalType().getTypePtr())) ft = arr->getElementType();
    if (!GlslTypeOf(ft) || ft->isPointerType() || IsStdVector(ft)) return false;
  }
  return GlslTypeOf(t).has_value();
}

// The GLSL name of a function that is a member or an operator: complex_norm, complex_op_mul, op_mul.
std::string KernelPrinter::FunctionName(const FunctionDecl* fd, const CXXRecordDecl* structSelf) const {
  std::string base = fd->isOverloadedOperator() ? "op_" + OperatorWord(fd->getOverloadedOperator(), fd->getNumParams() + (structSelf ? 1 : 0))
                                                : fd->getNameAsString();
  return structSelf ? structSelf->getNameAsString() + "_" + base : base;
}

// obj.method(args), on a plain struct.
std::string KernelPrinter::StructMethodCall(const CXXMemberCallExpr* call) {
  const CXXMethodDecl* method = call->getMethodDecl();
  std::map<unsigned, std::string> bindings;
  std::vector<std::string> args = HelperArgs(method, call, bindings);
  std::string s = EmitHelper(method, call->getBeginLoc(), false, bindings, method->getParent()) + "(" + Expr(call->getImplicitObjectArgument());
  for (auto& a : args) s += ", " + a;
  return s + ")";
}

// a OP b where OP is the struct's own (a member or a free function): a call of its GLSL function.
std::string KernelPrinter::StructOperatorCall(const CXXOperatorCallExpr* op) {
  auto* fd = op->getDirectCallee();
  std::map<unsigned, std::string> bindings;
  std::vector<std::string> args = HelperArgs(fd, op, bindings);
  if (auto* method = dyn_cast<CXXMethodDecl>(fd)) {
    std::string s = EmitHelper(method, op->getBeginLoc(), false, bindings, method->getParent()) + "(" + Expr(op->getArg(0));
    for (auto& a : args) s += ", " + a;
    return s + ")";
  }
  std::string s = EmitHelper(fd, op->getBeginLoc(), false, bindings) + "(";
  for (size_t i = 0; i < args.size(); ++i) s += (i ? ", " : "") + args[i];
  return s + ")";
}

// Whether an operator call runs the user's code (a struct's operator) rather than GLSL's own (on
// numbers, LiteMath vectors and matrices).
bool KernelPrinter::IsStructOperator(const CXXOperatorCallExpr* op) const {
  auto* fd = op->getDirectCallee();
  if (!fd || !fd->isOverloadedOperator()) return false;
  // Implicit and defaulted ones (copy assignment) are GLSL's assignment.
  if (auto* method = dyn_cast<CXXMethodDecl>(fd)) return method->isUserProvided() && IsPlainStruct(method->getParent());
  for (auto* p : fd->parameters())
    if (IsPlainStruct(p->getType().getNonReferenceType()->getAsCXXRecordDecl())) return true;
  return false;
}

// A struct's user-provided constructor: R R_ctor(params) { R self; members initialised; body; return self; }.
std::string KernelPrinter::ConstructorCall(const CXXConstructorDecl* ctor, const std::vector<const clang::Expr*>& args, SourceLocation loc) {
  const CXXRecordDecl* rd = ctor->getParent();
  const std::string type = rd->getNameAsString(), name = type + "_ctor";
  std::string call = name + "(";
  for (size_t i = 0; i < args.size(); ++i) call += (i ? ", " : "") + Expr(args[i]);
  call += ")";
  const FunctionDecl* def = nullptr;
  if (!ctor->hasBody(def) || !def) return Fail(loc, "the constructor of " + type + " is called in a kernel, but its body is not visible", "define it in a header");
  const auto* c = cast<CXXConstructorDecl>(def);
  if (m_emitted.count(c)) return call;
  if (m_inProgress.count(c)) return Fail(loc, "recursive constructor of " + type + " in a kernel", "");
  if (rd->getNumBases() > 0) return Fail(loc, "a constructor of " + type + ", a struct with base classes, in a kernel", "give the struct its fields directly");
  m_inProgress.insert(c);
  std::ostringstream os;
  os << "// from " << c->getQualifiedNameAsString() << "(";
  for (unsigned i = 0; i < c->getNumParams(); ++i) os << (i ? ", " : "") << c->getParamDecl(i)->getType().getAsString(m_ctx.getPrintingPolicy());
  os << ")\n" << type << " " << name << "(";
  for (unsigned i = 0; i < c->getNumParams(); ++i) os << (i ? ", " : "") << Declare(c->getParamDecl(i)->getType(), c->getParamDecl(i)->getNameAsString(), c->getParamDecl(i)->getLocation());
  os << ")\n{\n  " << type << " self;\n";
  const CXXRecordDecl* savedSelf = m_structSelf;
  m_structSelf = rd;
  bool delegated = false;
  for (auto* init : c->inits()) {
    if (init->isDelegatingInitializer()) {
      os << "  self = " << Expr(init->getInit()) << ";\n";
      delegated = true;
    }
  }
  // Members in declaration order, as C++ initialises them: from the initialiser list, else from
  // their default member initialiser; the others start undefined, as in C++.
  for (auto* f : rd->fields()) {
    if (delegated) break;
    const clang::Expr* value = nullptr;
    for (auto* init : c->inits())
      if (init->getMember() == f && init->isWritten()) value = init->getInit();
    if (!value && f->hasInClassInitializer()) value = f->getInClassInitializer();
    if (value) os << "  self." << SafeName(f->getNameAsString()) << " = " << Expr(value) << ";\n";
  }
  const bool savedCtor = m_inConstructor;
  m_inConstructor = true;
  if (auto* body = dyn_cast_or_null<CompoundStmt>(c->getBody()))
    for (auto* s : body->body()) os << Stmt(s, 1);
  m_inConstructor = savedCtor;
  m_structSelf = savedSelf;
  os << "  return self;\n}\n";
  m_inProgress.erase(c);
  m_emitted.insert(c);
  m_functions.push_back(os.str());
  return call;
}

// A constructor the translator must run as code: written by the user (not implicit, defaulted or a
// copy), of a plain struct.
bool KernelPrinter::IsUserConstructor(const CXXConstructorDecl* ctor) const {
  return ctor && IsPlainStruct(ctor->getParent()) && ctor->isUserProvided() && !ctor->isCopyOrMoveConstructor();
}

// LiteMath matrices' member functions: the columns of the language's matrices (MatrixObject).
std::string KernelPrinter::MatrixMethodCall(const CXXMemberCallExpr* call) {
  const std::string n = call->getMethodDecl()->getNameAsString();
  std::string m = Expr(call->getImplicitObjectArgument());
  m = MatrixObject(m);
  if (std::string row = n == "get_row" && call->getNumArgs() == 1 ? MatrixRow(call) : ""; !row.empty()) return row;
  if ((n == "get_col" || n == "col") && call->getNumArgs() == 1) return m + "[" + Expr(call->getArg(0)) + "]";
  if (n == "get_row" && call->getNumArgs() == 1) return "transpose(" + m + ")[" + Expr(call->getArg(0)) + "]";
  if (n == "set_col" && call->getNumArgs() == 2) return m + "[" + Expr(call->getArg(0)) + "] = " + Expr(call->getArg(1));
  if (n == "set_row" && call->getNumArgs() == 2) {  // one element per column, a statement each: m[c][i] = v[c]
    const auto* rd = call->getImplicitObjectArgument()->getType()->getAsCXXRecordDecl();
    const int columns = rd && rd->getName() == "float3x3" ? 3 : 4;
    if (ContainsCall(call->getArg(0)) || ContainsCall(call->getArg(1)))
      return Fail(call->getBeginLoc(), "LiteMath's set_row with a computed row or value in a kernel",
                  "compute the row index and the value into locals first: m.set_row(i, v)");
    const std::string i = Expr(call->getArg(0)), v = Expr(call->getArg(1));
    std::string out;
    for (int c = 0; c < columns; ++c) {  // ISPC's vectors have no subscript: LiteMath.isph's crt_set
      const std::string column = m + "[" + std::to_string(c) + "]", value = v + "." + "xyzw"[c];
      out += (c ? "; " : "") + (PassesBuffers() ? "crt_set(" + column + ", " + i + ", " + value + ")" : column + "[" + i + "] = " + value);
    }
    return out;
  }
  return Fail(call->getBeginLoc(), "LiteMath's " + call->getMethodDecl()->getQualifiedNameAsString() + " is not supported in kernels",
              "use m[col] (a column), transpose(m)[row], set_col, set_row, m * v");
}

}  // namespace crossrt::engine
