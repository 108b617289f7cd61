// The composed implementation passed to the methods of the objects it calls (paper 3.10: "a pointer
// to the BVHRT class can be passed inside the Intersect function, which is useful for accessing data
// stored within Intersect"). A traversal's leaf call `m_geom[g]->Intersect(ray, info, hit, this)`
// reaches `Intersect(..., const BVHRT* scene)`, whose body reads `scene->m_values[i]` and calls
// `scene->Helper(...)`. On the GPU the traversal's data are globals (its buffers, the class data),
// so the parameter and its argument are left out (ISPC keeps the parameter as a pointer to the class
// data, which holds the traversal's, and the dispatcher passes its own), and what is read through it
// prints as the traversal's own code prints it, under the traversal's prefix, into the traversal's
// Uses (which decide the kernel's buffers).
#include "print/KernelPrinter.h"

#include "analyse/AstQueries.h"

#include <algorithm>

using namespace clang;

namespace crossrt::engine {

bool KernelPrinter::PointsTo(QualType t, const CXXRecordDecl* cls) {
  if (!cls) return false;
  t = t.getNonReferenceType();
  if (t->isPointerType()) t = t->getPointeeType();
  const CXXRecordDecl* rd = t->getAsCXXRecordDecl();
  return rd && rd->getCanonicalDecl() == cls->getCanonicalDecl();
}

bool KernelPrinter::IsOwnerParam(const ParmVarDecl* p) const { return p && owner && PointsTo(p->getType(), owner->m_class); }

bool KernelPrinter::PassesSelf(const ParmVarDecl* p, const clang::Expr* arg) const {
  const clang::Expr* e = arg->IgnoreParenImpCasts();
  if (auto* uo = dyn_cast<UnaryOperator>(e); uo && uo->getOpcode() == UO_Deref) e = uo->getSubExpr()->IgnoreParenImpCasts();  // *this
  return p && isa<CXXThisExpr>(e) && PointsTo(p->getType(), m_class);
}

const ParmVarDecl* KernelPrinter::OwnerParamOf(const clang::Expr* e) const {
  if (!owner) return nullptr;
  auto* dr = dyn_cast<DeclRefExpr>(e->IgnoreParenImpCasts());
  auto* p = dr ? dyn_cast<ParmVarDecl>(dr->getDecl()) : nullptr;
  return IsOwnerParam(p) ? p : nullptr;
}

// `scene->Helper(args)`: the traversal's method, printed by a printer of the traversal's class under
// its prefix, with what it reads recorded in the owner's Uses. Its functions (and structs) go ahead of
// the object's, which call them: each shader that holds the object's code holds them too.
std::string KernelPrinter::OwnerCall(const CXXMemberCallExpr* call) {
  const CXXMethodDecl* method = call->getMethodDecl();
  if (method->isVirtual())
    return Fail(call->getBeginLoc(), "virtual call of " + method->getQualifiedNameAsString() + " through the traversal passed to an object's method",
                "call a non-virtual helper of the traversal");
  std::unique_ptr<KernelPrinter> sibling = Sibling(owner->m_class);
  KernelPrinter& helper = *sibling;
  helper.composedPrefix = owner->composedPrefix;
  helper.dataStruct = owner->DataStruct();
  helper.predeclaredStructs = predeclaredStructs;
  for (auto& x : m_structs) helper.predeclaredStructs.insert(x.name);  // declared here already
  std::map<unsigned, std::string> bindings;
  std::vector<std::string> args = HelperArgs(method, call, bindings);
  if (!ClassDataArgument().empty() && !method->isStatic())  // the traversal's methods take the class data first, as `self`
    args.insert(args.begin(), SafeName(OwnerParamOf(call->getImplicitObjectArgument())->getNameAsString()));
  const std::string callee = helper.EmitHelper(method, call->getBeginLoc(), false, bindings);
  if (!helper.m_uses.virtualCalls.empty())
    return Fail(call->getBeginLoc(), method->getQualifiedNameAsString() + " makes virtual calls; called from an object's method it cannot",
                "make the virtual calls in the traversal itself");
  for (auto* f : helper.m_uses.memberVectors) owner->m_uses.memberVectors.insert(f);
  for (auto* f : helper.m_uses.plainMembers) owner->m_uses.plainMembers.insert(f);
  owner->m_uses.sizeReads.insert(helper.m_uses.sizeReads.begin(), helper.m_uses.sizeReads.end());
  for (auto* fn : helper.m_uses.helpers) owner->m_uses.helpers.push_back(fn);
  for (auto& x : helper.Structs()) {  // by name: this printer declares them no more
    if (std::none_of(m_structs.begin(), m_structs.end(), [&](const GlslDecl& y) { return y.name == x.name; })) m_structs.push_back(x);
    predeclaredStructs.insert(x.name);
  }
  for (auto& x : helper.Constants())
    if (std::find(m_constants.begin(), m_constants.end(), x) == m_constants.end()) m_constants.push_back(x);
  for (auto& x : helper.Functions())
    if (std::find(m_functions.begin(), m_functions.end(), x) == m_functions.end()) m_functions.push_back(x);
  std::string s = callee + "(";
  for (size_t i = 0; i < args.size(); ++i) s += (i ? ", " : "") + args[i];
  return s + ")";
}

}  // namespace crossrt::engine
