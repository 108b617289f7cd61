// Lambdas in kernels: `auto f = [k](float x) { return k * x; }; ... f(v)`, or a lambda called where
// it is written. Neither GLSL nor ISPC has closures, so each lambda becomes a function of its own,
// named after the function it is written in and the local that holds it
// (kernel1D_Run_f), whose parameters are the lambda's and then its captures: by copy as values,
// by reference as inout (GLSL) or references (ISPC), `this` as the class data it reaches. The
// local itself prints as nothing.
#include "print/KernelPrinter.h"

#include "analyse/AstQueries.h"

#include <sstream>

using namespace clang;

namespace crossrt::engine {

namespace {

// The lambda a call's callee is: a local initialised with one, or the lambda itself. Null else.
const LambdaExpr* CalledLambda(const clang::Expr* callee, const VarDecl** holder) {
  callee = callee->IgnoreParenImpCasts();
  if (auto* le = dyn_cast<LambdaExpr>(callee)) return le;
  auto* dr = dyn_cast<DeclRefExpr>(callee);
  auto* vd = dr ? dyn_cast<VarDecl>(dr->getDecl()) : nullptr;
  if (!vd || !vd->hasLocalStorage() || !vd->getInit()) return nullptr;
  const clang::Expr* init = vd->getInit()->IgnoreImplicit();
  if (auto* construct = dyn_cast<CXXConstructExpr>(init); construct && construct->getNumArgs() == 1)
    init = construct->getArg(0)->IgnoreImplicit();  // a copy of the closure (C++14 without elision)
  *holder = vd;
  return dyn_cast<LambdaExpr>(init);
}

}  // namespace

std::string KernelPrinter::LambdaCall(const CXXOperatorCallExpr* op) {
  const VarDecl* holder = nullptr;
  const LambdaExpr* lambda = CalledLambda(op->getArg(0), &holder);
  if (!lambda)
    return Fail(op->getBeginLoc(), "a call of a lambda the kernel does not hold in a local it initialises with the lambda",
                "write `auto f = [...](...) { ... };` in the kernel and call f");
  auto* enclosing = dyn_cast<FunctionDecl>(lambda->getLambdaClass()->getDeclContext());
  const std::string name = EmitLambda(lambda, composedPrefix + (enclosing ? enclosing->getNameAsString() : std::string("kernel")) + "_" +
                                                  (holder ? holder->getNameAsString() : "lambda" + std::to_string(m_lambdaNames.size())));
  std::string args;
  for (unsigned i = 1; i < op->getNumArgs(); ++i) args += (args.empty() ? "" : ", ") + Expr(op->getArg(i));
  for (const LambdaCapture& capture : lambda->captures()) {
    if (capture.capturesThis()) {
      if (std::string data = ClassDataArgument(); !data.empty()) args = data + std::string(args.empty() ? "" : ", ") + args;
      continue;
    }
    if (auto* var = capture.capturesVariable() ? dyn_cast<VarDecl>(capture.getCapturedVar()) : nullptr)
      args += (args.empty() ? "" : ", ") + LocalName(var);
  }
  return name + "(" + args + ")";
}

std::string KernelPrinter::EmitLambda(const LambdaExpr* lambda, const std::string& name) {
  if (auto known = m_lambdaNames.find(lambda); known != m_lambdaNames.end()) return known->second;
  const CXXMethodDecl* call = lambda->getCallOperator();
  if (lambda->isGenericLambda())
    return Fail(lambda->getBeginLoc(), "a generic lambda (auto parameters) in a kernel", "give its parameters types: [](float x) { ... }");
  m_lambdaNames[lambda] = name;
  std::ostringstream os;
  auto ret = Type(call->getReturnType(), lambda->getBeginLoc());
  os << "// from the lambda at line " << m_ctx.getSourceManager().getSpellingLineNumber(lambda->getBeginLoc()) << " of "
     << (isa<FunctionDecl>(lambda->getLambdaClass()->getDeclContext())
             ? cast<FunctionDecl>(lambda->getLambdaClass()->getDeclContext())->getQualifiedNameAsString()
             : std::string("the kernel"))
     << "\n"
     << FunctionQualifiers(call) << (ret ? *ret : "void") << " " << name << "(";
  std::string params;
  auto add = [&](const std::string& p) { params += (params.empty() ? "" : ", ") + p; };
  bool capturesThis = false;
  for (const LambdaCapture& capture : lambda->captures()) capturesThis = capturesThis || capture.capturesThis();
  if (std::string data = ClassDataParameter(); capturesThis && !data.empty()) add(data);
  for (const ParmVarDecl* p : call->parameters()) {
    const QualType t = p->getType();
    if (t->isPointerType()) return Fail(p->getLocation(), "a lambda with a pointer parameter in a kernel", "pass the element, or an index into the buffer");
    add(t->isReferenceType() && !t.getNonReferenceType().isConstQualified() ? WritableParam(t.getNonReferenceType(), p->getNameAsString(), p->getLocation())
                                                                              : Declare(t.getNonReferenceType(), p->getNameAsString(), p->getLocation()));
  }
  for (const LambdaCapture& capture : lambda->captures()) {
    if (capture.capturesThis()) continue;  // members: the class data, as in the kernel
    if (capture.capturesVLAType() || !capture.capturesVariable())
      return Fail(capture.getLocation(), "this capture of a lambda in a kernel", "capture locals by copy or by reference");
    auto* var = dyn_cast<VarDecl>(capture.getCapturedVar());
    if (!var || var->isInitCapture())
      return Fail(capture.getLocation(), "an init-capture of a lambda in a kernel", "declare the value as a local before the lambda and capture it");
    const QualType t = var->getType().getNonReferenceType();
    if (t->isPointerType() || var->getType()->isReferenceType())
      return Fail(capture.getLocation(), "a lambda in a kernel capturing '" + var->getNameAsString() + "', a pointer or reference",
                  "capture the value it refers to, copied into a local first");
    const bool byReference = capture.getCaptureKind() == LCK_ByRef && !t.isConstQualified();
    add(byReference ? WritableParam(t, LocalName(var), var->getLocation()) : Declare(t, LocalName(var), var->getLocation()));
  }
  os << params << ")\n" << FunctionBody(call->getBody());
  m_uses.helpers.push_back(call);  // its writes to members count as a helper's
  m_functions.push_back(os.str());
  return name;
}

}  // namespace crossrt::engine
