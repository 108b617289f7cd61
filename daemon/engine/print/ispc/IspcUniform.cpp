// ISPC uniformity: which values of a kernel every lane of a gang shares. The printer declares a
// loop variable `uniform` when its start and step are shared (a kernel's scalar parameters, members,
// the outer loops of a 2D or 3D nest, constants), its condition is shared where the variable is
// (k < n, k + 1 < top, with n and top shared), and nothing else changes it: the loop
// then runs once per gang, and what it indexes with the variable (m_weights[k + m_radius]) is one
// load for all lanes instead of a gather, and a shared value.
//
// And the gang of Gang.h: a CRT_UNIFORM local is `uniform`, and every value assigned to it must be
// shared (reported at the user's line otherwise, not as an ISPC error in the generated file);
// crossrt::AnyLane, AllLanes, FirstLane, MinOverLanes, GangSize, LaneIndex, LaneBits, LaneValue and
// FromLane are ISPC's any, all, extract at the lowest active lane, reduce_min, programCount,
// programIndex, packmask, extract and shuffle, and LaneOf and LaneOfQuad a load of a vector's
// components across the lanes (crt_lane_of, crt_lane_of_quad);
// a loop stepping by GangSize() runs `unmasked`; AllLanesOn tests lanemask(), and the branch of
// an `if` it guards is `unmasked`. Part of IspcPrinter (IspcPrinter.h).
#include "analyse/AstQueries.h"
#include "print/ispc/IspcPrinter.h"
#include "print/PrinterParts.h"
#include "print/GlslTypes.h"
#include "analyse/WriteVisitor.h"

using namespace clang;

namespace crossrt::engine {

// Storage the gang shares: a uniform local (CRT_UNIFORM, a uniform loop's variable), an element of a
// member vector at a shared index, and a field, an array element or a vector component of those at
// shared indices.
bool IspcPrinter::SharedPlace(const clang::Expr* e) const {
  e = e->IgnoreParenImpCasts();
  if (auto* dr = dyn_cast<DeclRefExpr>(e)) return uniformValues.count(dr->getDecl()) > 0;
  if (auto* me = dyn_cast<MemberExpr>(e)) return !me->isArrow() && SharedPlace(me->getBase());
  if (auto* as = dyn_cast<ArraySubscriptExpr>(e)) return SharedPlace(as->getBase()) && Uniform(as->getIdx());
  auto* op = dyn_cast<CXXOperatorCallExpr>(e);
  if (!op || op->getOperator() != OO_Subscript || op->getNumArgs() != 2 || !Uniform(op->getArg(1))) return false;
  if (IsLiteMathType(op->getArg(0)->getType().getNonReferenceType(), nullptr)) return SharedPlace(op->getArg(0));  // v[i]
  auto* f = ThisMemberField(op->getArg(0));
  return f && IsStdVector(f->getType()) && !selfClass && !m_structSelf;
}

bool IspcPrinter::Uniform(const clang::Expr* e) const {
  e = e->IgnoreParenImpCasts();
  if (isa<IntegerLiteral, FloatingLiteral, CXXBoolLiteralExpr, CharacterLiteral>(e)) return true;
  if (auto* call = dyn_cast<CallExpr>(e); call && IsGangFunction(call->getDirectCallee())) {
    const std::string name = call->getDirectCallee()->getNameAsString();
    if (name == "LaneIndex" || name == "LaneOf" || name == "LaneOfQuad" || name == "FromLane") return false;  // values that differ in every lane
    if (name == "FirstLane" || name == "MinOverLanes" || name == "LaneValue") return call->getArg(0)->getType()->isArithmeticType();
    return true;
  }
  if (auto* call = dyn_cast<CallExpr>(e); call && call->getDirectCallee() && call->getNumArgs() == 1) {  // a bit count of a shared value
    const unsigned id = call->getDirectCallee()->getBuiltinID();
    if (id == Builtin::BI__builtin_ctz || id == Builtin::BI__builtin_clz || id == Builtin::BI__builtin_popcount) return Uniform(call->getArg(0));
  }
  if ((isa<MemberExpr, ArraySubscriptExpr, CXXOperatorCallExpr>(e)) && e->getType()->isArithmeticType() && SharedPlace(e)) return true;
  if (auto* c = dyn_cast<CStyleCastExpr>(e)) return c->getType()->isArithmeticType() && Uniform(c->getSubExpr());
  if (auto* c = dyn_cast<CXXFunctionalCastExpr>(e)) return c->getType()->isArithmeticType() && Uniform(c->getSubExpr());
  if (auto* dr = dyn_cast<DeclRefExpr>(e)) {
    if (uniformValues.count(dr->getDecl())) return true;
    auto* vd = dyn_cast<VarDecl>(dr->getDecl());  // a constant (constexpr, or const with a constant initialiser)
    return vd && vd->getType().isConstQualified() && vd->getType()->isArithmeticType() && vd->getInit() &&
           vd->getInit()->isEvaluatable(m_ctx);
  }
  if (auto* me = dyn_cast<MemberExpr>(e)) {  // a scalar data member: self->m_x (a composed object's: self->m_pAccelStruct_m_x)
    auto* f = dyn_cast<FieldDecl>(me->getMemberDecl());
    return f && isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts()) && f->getType()->isArithmeticType() && !selfClass &&
           !m_structSelf;  // in a plain struct's method, `this` is the struct (a varying value), not the class
  }
  if (auto* mc = dyn_cast<CXXMemberCallExpr>(e)) {  // a member vector's size() (self->m_v_size), an image's width() or height()
    const CXXMethodDecl* method = mc->getMethodDecl();
    if (!method || !composedPrefix.empty() || selfClass || m_structSelf) return false;
    const clang::Expr* object = mc->getImplicitObjectArgument();
    if (method->getName() == "width" || method->getName() == "height") {
      if (IsImage2D(object->getType().getNonReferenceType())) return true;
      // a texture of a member array at a shared index (self->m_textures[k].width)
      auto* op = dyn_cast<CXXOperatorCallExpr>(object->IgnoreParenImpCasts());
      return op && op->getOperator() == OO_Subscript && op->getNumArgs() == 2 && ThisMemberField(op->getArg(0)) &&
             IsTextureArray(ThisMemberField(op->getArg(0))->getType()) && Uniform(op->getArg(1));
    }
    auto* f = ThisMemberField(object);
    return f && method->getName() == "size" && IsStdVector(f->getType());
  }
  if (auto* op = dyn_cast<CXXOperatorCallExpr>(e); op && op->getOperator() == OO_Subscript && op->getNumArgs() == 2) {
    // an element of a member vector at a shared index (self->m_v[k]: one load for the gang)
    if (selfClass || m_structSelf || !op->getType()->isArithmeticType()) return false;
    auto* f = ThisMemberField(op->getArg(0));
    return f && IsStdVector(f->getType()) && Uniform(op->getArg(1));
  }
  if (auto* uo = dyn_cast<UnaryOperator>(e))
    return (uo->getOpcode() == UO_Minus || uo->getOpcode() == UO_Plus || uo->getOpcode() == UO_Not || uo->getOpcode() == UO_LNot) &&
           Uniform(uo->getSubExpr());
  if (auto* bo = dyn_cast<BinaryOperator>(e))
    return !bo->isAssignmentOp() && bo->getOpcode() != BO_Comma && Uniform(bo->getLHS()) && Uniform(bo->getRHS());
  if (auto* co = dyn_cast<ConditionalOperator>(e))
    return Uniform(co->getCond()) && Uniform(co->getTrueExpr()) && Uniform(co->getFalseExpr());
  return false;
}

const VarDecl* IspcPrinter::UniformLoop(const ForStmt* fs) {
  // for (int k = start; condition; ++k) with start shared and a condition shared where k is
  // (k < bound, k + 1 < top, 2 * k < n, with bound, top and n shared),
  auto* ds = dyn_cast_or_null<DeclStmt>(fs->getInit());
  auto* v = ds && ds->isSingleDecl() ? dyn_cast<VarDecl>(ds->getSingleDecl()) : nullptr;
  if (!v || !v->getType()->isIntegerType() || !v->getInit() || !Uniform(v->getInit()) || !fs->getCond()) return nullptr;
  const bool known = uniformValues.count(v) > 0;
  uniformValues.insert(v);
  const bool sharedCond = Uniform(fs->getCond());
  if (!known) uniformValues.erase(v);
  if (!sharedCond) return nullptr;
  // a step of ++k, k++, --k, k--, k += shared or k -= shared,
  const clang::Expr* inc = fs->getInc() ? fs->getInc()->IgnoreParenImpCasts() : nullptr;
  bool step = false;
  if (auto* uo = dyn_cast_or_null<UnaryOperator>(inc)) step = uo->isIncrementDecrementOp() && NamedVar(uo->getSubExpr()) == v;
  if (auto* ca = dyn_cast_or_null<CompoundAssignOperator>(inc))
    step = (ca->getOpcode() == BO_AddAssign || ca->getOpcode() == BO_SubAssign) && NamedVar(ca->getLHS()) == v && Uniform(ca->getRHS());
  if (!step) return nullptr;
  // and a body that neither changes k nor leaves the loop early in some lanes only: a break,
  // continue or return only under conditions every lane shares (k taken as shared: if it is, so
  // are they, and the gang leaves together), as `if (m_nodes[node].child[lane] == kNoChild) break;`.
  struct Body : WriteVisitor<Body> {
    const IspcPrinter* printer;
    const VarDecl* v;
    bool bad = false;
    int varyingIfs = 0, innerLoops = 0, innerSwitches = 0;  // around the statement being visited
    void Written(const clang::Expr* target, SourceLocation) { bad |= WrittenVar(target) == v; }
    bool VisitUnaryOperator(UnaryOperator* uo) {
      if (uo->getOpcode() == UO_AddrOf) bad |= WrittenVar(uo->getSubExpr()) == v;
      return WriteVisitor<Body>::VisitUnaryOperator(uo);
    }
    bool TraverseIfStmt(IfStmt* is) {
      const bool shared = printer->Uniform(is->getCond());
      if (is->getInit()) TraverseStmt(is->getInit());
      TraverseStmt(is->getCond());
      varyingIfs += shared ? 0 : 1;
      TraverseStmt(is->getThen());
      if (is->getElse()) TraverseStmt(is->getElse());
      varyingIfs -= shared ? 0 : 1;
      return true;
    }
    using Base = RecursiveASTVisitor<Body>;
    // A break in an inner loop or switch leaves that; a continue in an inner loop continues that.
    bool TraverseForStmt(ForStmt* s) { ++innerLoops; const bool r = Base::TraverseForStmt(s); --innerLoops; return r; }
    bool TraverseWhileStmt(WhileStmt* s) { ++innerLoops; const bool r = Base::TraverseWhileStmt(s); --innerLoops; return r; }
    bool TraverseDoStmt(DoStmt* s) { ++innerLoops; const bool r = Base::TraverseDoStmt(s); --innerLoops; return r; }
    bool TraverseCXXForRangeStmt(CXXForRangeStmt* s) { ++innerLoops; const bool r = Base::TraverseCXXForRangeStmt(s); --innerLoops; return r; }
    bool TraverseSwitchStmt(SwitchStmt* s) {  // its cases run under its condition, as an if's branches do
      const int varying = printer->Uniform(s->getCond()) ? 0 : 1;
      ++innerSwitches;
      varyingIfs += varying;
      const bool r = Base::TraverseSwitchStmt(s);
      varyingIfs -= varying;
      --innerSwitches;
      return r;
    }
    bool VisitBreakStmt(BreakStmt*) { bad |= innerLoops == 0 && innerSwitches == 0 && varyingIfs > 0; return true; }
    bool VisitContinueStmt(ContinueStmt*) { bad |= innerLoops == 0 && varyingIfs > 0; return true; }
    bool VisitReturnStmt(ReturnStmt*) { bad |= varyingIfs > 0 || innerLoops > 0; return true; }  // (an inner loop's lanes may part)
    bool VisitGotoStmt(GotoStmt*) { return !(bad = true); }
  } body;
  body.printer = this;
  body.v = v;
  uniformValues.insert(v);
  body.TraverseStmt(const_cast<clang::Stmt*>(fs->getBody()));
  if (!known) uniformValues.erase(v);
  return body.bad ? nullptr : v;
}

// ---- the gang (Gang.h) ----

std::string IspcPrinter::GangCall(const FunctionDecl* fd, const CallExpr* call) {
  const std::string name = fd->getNameAsString();
  if (name == "GangSize") return "programCount";
  if (name == "AllLanesOn") return "(popcnt(lanemask()) == programCount)";
  if (name == "LaneIndex") return "programIndex";
  const std::string value = Expr(call->getArg(0));
  if (name == "LaneOf" || name == "LaneOfQuad") {
    // Components first, first + 1, ... of a 4-vector across the lanes (LaneOfQuad: 0 to 3 in each quad
    // of lanes): from memory the gang shares, a load.
    const QualType vt = call->getArg(0)->getType().getNonReferenceType().getUnqualifiedType();
    if (!IsLiteMathType(vt, "float4") && !IsLiteMathType(vt, "int4") && !IsLiteMathType(vt, "uint4"))
      return Fail(call->getArg(0)->getExprLoc(), "crossrt::" + name + " of a '" + vt.getAsString(m_ctx.getPrintingPolicy()) + "'",
                  "pass a LiteMath float4, int4 or uint4");
    if (name == "LaneOfQuad")
      return SharedPlace(call->getArg(0)) ? "crt_lane_of_quad(&(" + value + "))" : "crt_lane_of_quad(" + value + ")";
    if (!Uniform(call->getArg(1)))
      return Fail(call->getArg(1)->getExprLoc(), "the first component of crossrt::LaneOf may differ between the lanes of an ISPC gang",
                  "pass a component every lane shares: a constant, a CRT_UNIFORM local or a shared loop's variable");
    const std::string first = Expr(call->getArg(1));
    return SharedPlace(call->getArg(0)) ? "crt_lane_of(&(" + value + "), " + first + ")" : "crt_lane_of(" + value + ", " + first + ")";
  }
  if (name == "AnyLane") return "any(" + value + ")";
  if (name == "AllLanes") return "all(" + value + ")";
  if (name == "LaneBits") return "((uniform uint)packmask(" + value + "))";
  // FirstLane, LaneValue, FromLane and MinOverLanes: of a 32-bit number (a bool too, but for MinOverLanes).
  const QualType t = call->getArg(0)->getType().getCanonicalType().getUnqualifiedType();
  const bool bit32 = t->isArithmeticType() && !t->isBooleanType() && m_ctx.getTypeSize(t) == 32;
  if (!bit32 && !(name != "MinOverLanes" && t->isBooleanType()))
    return Fail(call->getArg(0)->getExprLoc(), "crossrt::" + name + " of a '" + t.getAsString(m_ctx.getPrintingPolicy()) + "'",
                "pass an int, unsigned, float" + std::string(name != "MinOverLanes" ? " or bool" : "") + ", one field at a time");
  if (name == "LaneValue" && !Uniform(call->getArg(1)))
    return Fail(call->getArg(1)->getExprLoc(), "the lane of crossrt::LaneValue may differ between the lanes of an ISPC gang",
                "pass a lane every lane shares: a CRT_UNIFORM local, or FirstLane of a parameter");
  if (name == "LaneValue") return "crt_lane_value(" + value + ", " + Expr(call->getArg(1)) + ")";
  if (name == "FromLane") return "crt_from_lane(" + value + ", " + Expr(call->getArg(1)) + ")";
  return (name == "FirstLane" ? "crt_first_lane(" : "reduce_min(") + value + ")";
}

// Whether e is crossrt::AllLanesOn() or a conjunction (&&) with it as one of its terms.
static bool ConjoinsAllLanesOn(const clang::Expr* e) {
  e = e->IgnoreParenImpCasts();
  if (auto* bo = dyn_cast<BinaryOperator>(e); bo && bo->getOpcode() == BO_LAnd)
    return ConjoinsAllLanesOn(bo->getLHS()) || ConjoinsAllLanesOn(bo->getRHS());
  auto* call = dyn_cast<CallExpr>(e);
  return call && IsGangFunction(call->getDirectCallee()) && call->getDirectCallee()->getName() == "AllLanesOn";
}

// The first statement in s that leaves it: a return, or a break or continue outside the loops and
// switches within s (nullptr if none).
static const clang::Stmt* ExitFrom(const clang::Stmt* s) {
  struct Exits : RecursiveASTVisitor<Exits> {
    const clang::Stmt* found = nullptr;
    int inner = 0;  // loops and switches around the statement being visited
    bool VisitReturnStmt(ReturnStmt* r) { found = found ? found : r; return true; }
    bool VisitBreakStmt(BreakStmt* b) { found = found || inner ? found : b; return true; }
    bool VisitContinueStmt(ContinueStmt* c) { found = found || inner ? found : c; return true; }
    using Base = RecursiveASTVisitor<Exits>;
    bool TraverseForStmt(ForStmt* f) { ++inner; Base::TraverseForStmt(f); --inner; return true; }
    bool TraverseWhileStmt(WhileStmt* w) { ++inner; Base::TraverseWhileStmt(w); --inner; return true; }
    bool TraverseDoStmt(DoStmt* d) { ++inner; Base::TraverseDoStmt(d); --inner; return true; }
    bool TraverseCXXForRangeStmt(CXXForRangeStmt* f) { ++inner; Base::TraverseCXXForRangeStmt(f); --inner; return true; }
    bool TraverseSwitchStmt(SwitchStmt* w) { ++inner; Base::TraverseSwitchStmt(w); --inner; return true; }
    bool TraverseLambdaExpr(LambdaExpr*) { return true; }  // a lambda's return leaves the lambda
  } exits;
  exits.TraverseStmt(const_cast<clang::Stmt*>(s));
  return exits.found;
}

// Whether fs steps by crossrt::GangSize(): `for (int first = a; first < b; first += crossrt::GangSize())`,
// whose lanes share out its items (item first + LaneIndex() in each lane).
static bool StepsByGangSize(const ForStmt* fs) {
  auto* ca = dyn_cast_or_null<CompoundAssignOperator>(fs->getInc() ? fs->getInc()->IgnoreParenImpCasts() : nullptr);
  auto* call = ca && ca->getOpcode() == BO_AddAssign ? dyn_cast<CallExpr>(ca->getRHS()->IgnoreParenImpCasts()) : nullptr;
  return call && IsGangFunction(call->getDirectCallee()) && call->getDirectCallee()->getName() == "GangSize";
}

// A loop the gang runs together (UniformLoop) whose lanes share out its items, by a step of
// crossrt::GangSize(): every lane of the gang takes an item, also the lanes that a branch, a loop or
// a return had switched off, so ISPC runs it `unmasked` (crossrt::LaneBits and LaneValue then see
// every lane, and a gang with some queries done still counts its share). Such a loop may write only
// its own locals and CRT_UNIFORM ones, and may not return: an unmasked write to anything else would
// write the lanes that are off too.
std::string IspcPrinter::ForLoop(const ForStmt* fs, int indent) {
  if (!StepsByGangSize(fs) || !UniformLoop(fs)) return KernelPrinter::ForLoop(fs, indent);
  struct Writes : WriteVisitor<Writes> {
    const IspcPrinter* printer;
    std::set<const VarDecl*> own;  // the loop's variable and the locals declared in its body
    const clang::Expr* bad = nullptr;
    const ReturnStmt* ret = nullptr;
    void Written(const clang::Expr* target, SourceLocation) {
      const VarDecl* v = WrittenVar(target);
      if (!bad && !(v && (own.count(v) || printer->uniformValues.count(v)))) bad = target;
    }
    bool VisitVarDecl(VarDecl* vd) { own.insert(vd); return true; }
    bool VisitCallExpr(CallExpr* call) { ReferenceArguments(call); return true; }
    bool VisitReturnStmt(ReturnStmt* r) { ret = ret ? ret : r; return true; }
    bool TraverseLambdaExpr(LambdaExpr*) { return true; }
  } writes;
  writes.printer = this;
  if (auto* ds = dyn_cast_or_null<DeclStmt>(fs->getInit()))
    for (auto* d : ds->decls())
      if (auto* vd = dyn_cast<VarDecl>(d)) writes.own.insert(vd);
  writes.TraverseStmt(const_cast<clang::Stmt*>(fs->getBody()));
  const std::string hint = "a loop stepping by crossrt::GangSize() runs on every lane of the gang, those switched off before it too";
  if (writes.ret)
    return Fail(writes.ret->getBeginLoc(), "'return' inside a loop that shares its items out over the gang's lanes",
                "ISPC runs the loop unmasked (" + hint + "), and cannot leave it so: keep the result in a CRT_UNIFORM local and return after the loop"),
           "";
  if (writes.bad)
    return Fail(writes.bad->getExprLoc(), "a write to '" + TrimmedSourceText(m_ctx, writes.bad->getSourceRange()) +
                                              "' inside a loop that shares its items out over the gang's lanes",
                hint + ", and would write theirs: write the loop's own locals and CRT_UNIFORM locals (crossrt::LaneBits, LaneValue), and the rest after it"),
           "";
  const std::string pad(indent * 2, ' ');
  return pad + "unmasked  // the lanes share out this loop's items (a step of crossrt::GangSize()): every lane takes part\n" + pad + "{\n" +
         KernelPrinter::ForLoop(fs, indent + 1) + pad + "}\n";
}

// `if (crossrt::AllLanesOn() && ...)` with a condition every lane shares: its then-branch runs with
// every lane on, so it is `unmasked`, and ISPC compiles it with the mask known (Gang.h). The branch
// may not return, break or continue out of itself: ISPC 1.28 mixes up which lanes have returned
// after a return inside `unmasked` (a test image differed in 8 pixels of 6144).
std::string IspcPrinter::ThenBranch(const clang::IfStmt* is, int indent) {
  if (!ConjoinsAllLanesOn(is->getCond()) || !Uniform(is->getCond())) return KernelPrinter::ThenBranch(is, indent);
  if (const clang::Stmt* exit = ExitFrom(is->getThen()))
    return Fail(exit->getBeginLoc(), std::string("'") + (isa<ReturnStmt>(exit) ? "return" : isa<BreakStmt>(exit) ? "break" : "continue") +
                                         "' inside a crossrt::AllLanesOn() branch",
                "ISPC runs the branch unmasked, and cannot leave it so: assign the result to a local declared before the if, and "
                "return (break, continue) after it"),
           "";
  const std::string pad(2 * (indent + 1), ' ');
  std::string body = Stmt(is->getThen(), isa<CompoundStmt>(is->getThen()) ? indent + 1 : indent + 2);
  if (!isa<CompoundStmt>(is->getThen())) body = pad + "{\n" + body + pad + "}\n";
  return pad + "unmasked  // every lane is on (crossrt::AllLanesOn): the mask is known, local structs stay in registers\n" + body;
}

// A CRT_UNIFORM local: `uniform`, if it holds numbers and starts shared. And a constant (a const
// number with a constant initialiser, `const int numSamples = 16;`), which Uniform() takes as
// shared: declared varying, its uses in `(uniform float)numSamples` would not compile.
std::string IspcPrinter::LocalQualifier(const VarDecl* vd) {
  if (!IsUniformLocal(vd)) {
    const QualType t = vd->getType();
    if (t.isConstQualified() && t->isArithmeticType() && vd->getInit() && vd->getInit()->isEvaluatable(m_ctx)) return "uniform ";
    return "";
  }
  const QualType t = vd->getType();
  if (t->isReferenceType() || !m_ctx.getBaseElementType(t)->isArithmeticType()) {
    Fail(vd->getLocation(), "CRT_UNIFORM local '" + vd->getNameAsString() + "' of type '" + t.getAsString(m_ctx.getPrintingPolicy()) + "'",
         "a gang shares numbers and arrays of numbers: declare the struct's fields as CRT_UNIFORM locals of their own");
    return "";
  }
  if (const clang::Expr* init = vd->getInit()) {
    std::vector<const clang::Expr*> values = {init};
    if (auto* list = dyn_cast<InitListExpr>(init->IgnoreImplicit())) values.assign(list->inits().begin(), list->inits().end());
    for (const clang::Expr* value : values)
      if (!isa<ImplicitValueInitExpr>(value) && !Uniform(value)) SharedValueExpected(vd, value, false);
  }
  uniformValues.insert(vd);
  return "uniform ";
}

// `target = value` (or op=) where target is a CRT_UNIFORM local or its element: value, and the
// element's index, must be shared.
void IspcPrinter::CheckSharedAssignment(const clang::Expr* target, const clang::Expr* value) {
  target = target->IgnoreParenImpCasts();
  const clang::Expr* index = nullptr;
  if (auto* as = dyn_cast<ArraySubscriptExpr>(target)) {
    index = as->getIdx();
    target = as->getBase()->IgnoreParenImpCasts();
  }
  auto* dr = dyn_cast<DeclRefExpr>(target);
  auto* vd = dr ? dyn_cast<VarDecl>(dr->getDecl()) : nullptr;
  if (!IsUniformLocal(vd)) return;
  if (index && !Uniform(index)) SharedValueExpected(vd, index, true);
  else if (!Uniform(value)) SharedValueExpected(vd, value, false);
}

void IspcPrinter::ReferenceArgument(const ParmVarDecl* p, const clang::Expr* arg) {
  const clang::Expr* named = arg->IgnoreParenImpCasts();
  if (auto* as = dyn_cast<ArraySubscriptExpr>(named)) named = as->getBase()->IgnoreParenImpCasts();
  auto* dr = dyn_cast<DeclRefExpr>(named);
  auto* vd = dr ? dyn_cast<VarDecl>(dr->getDecl()) : nullptr;
  if (IsUniformLocal(vd))
    Fail(arg->getExprLoc(), "CRT_UNIFORM '" + vd->getNameAsString() + "' is passed to reference parameter '" + p->getNameAsString() +
                                "', which holds one value per lane on ISPC",
         "return the new value and assign it, or copy it into a local without CRT_UNIFORM around the call");
}

void IspcPrinter::SharedValueExpected(const VarDecl* vd, const clang::Expr* where, bool isIndex) {
  Fail(where->getExprLoc(),
       std::string(isIndex ? "an index" : "a value") + " that may differ between the lanes of an ISPC gang " + (isIndex ? "into" : "is assigned to") +
           " CRT_UNIFORM '" + vd->getNameAsString() + "'",
       "assign what every lane shares (constants, members, CRT_UNIFORM locals, crossrt::AnyLane, FirstLane, LaneValue, LaneBits or MinOverLanes of a "
       "value), or declare '" + vd->getNameAsString() + "' without CRT_UNIFORM");
}

}  // namespace crossrt::engine
