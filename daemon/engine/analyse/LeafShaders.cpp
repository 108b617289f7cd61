// Level 3 in composed code (paper 3.10): loops over leaves whose bodies call virtual intersection
// functions, and traversals that call them with a CRT_LeafInfo at their leaves (the paper's listing
// 2), become traces of a ray tracing pipeline, with an intersection shader per leaf class and a hit
// and a miss shader per call. Takes the traversal's loops; gives Kernel::leaves and the shaders.
#include "analyse/LeafShaders.h"
#include "generate/CodeGenSupport.h"
#include "generate/GeneratedNames.h"
#include "print/glsl/GlslPrinter.h"

#include "analyse/AstQueries.h"
#include "analyse/Composition.h"
#include "analyse/LoopShape.h"
#include "analyse/Members.h"
#include "analyse/VirtualCalls.h"
#include "analyse/WriteVisitor.h"

#include <algorithm>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

namespace {

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
const VarDecl* LeafLoopVariable(ASTContext& ctx, const clang::Stmt* loop, const CXXMemberCallExpr* call) {
  auto* fs = dyn_cast<ForStmt>(loop);
  LoopHeader h;
  if (!fs || !LoopShapeProblem(ctx, fs, h).empty() || h.inclusive) return nullptr;
  auto* zero = dyn_cast<IntegerLiteral>(h.start->IgnoreParenImpCasts());
  if (!zero || zero->getValue() != 0) return nullptr;
  const VarDecl* var = h.var;
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
  std::vector<std::pair<const VarDecl*, SourceLocation>> outerWrites;  // every write to a variable declared before it
  void Written(const clang::Expr* target, SourceLocation loc) {
    const VarDecl* vd = WrittenVar(target);
    if (vd && !inner.count(vd)) {
      Note(loc, "it writes '" + vd->getNameAsString() + "', declared before the loop");
      outerWrites.push_back({vd, loc});
    }
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

// Whether a statement of `fn`'s body after `loop` names `vd`.
bool UsedAfter(const FunctionDecl* fn, const clang::Stmt* loop, const VarDecl* vd) {
  struct Finder : RecursiveASTVisitor<Finder> {
    const VarDecl* vd;
    bool found = false;
    bool VisitDeclRefExpr(DeclRefExpr* dr) {
      found |= dr->getDecl() == vd;
      return !found;
    }
  };
  auto* body = dyn_cast_or_null<CompoundStmt>(fn->getBody());
  if (!body) return false;
  bool after = false;
  for (const clang::Stmt* st : body->body()) {
    if (after) {
      Finder f;
      f.vd = vd;
      f.TraverseStmt(const_cast<clang::Stmt*>(st));
      if (f.found) return true;
    }
    after |= st == loop;
  }
  return false;
}

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

// The paper's leaf information (CrossRT.h's CRT_LeafInfo): its fields as the hardware knows them.
std::string LeafInfoFrom(const CXXRecordDecl* info, const std::string& var) {
  static const std::map<std::string, std::string> builtins = {
      {"aabbId", "uint(gl_PrimitiveID)"},  {"primId", "uint(gl_PrimitiveID)"}, {"instId", "uint(gl_InstanceID)"},
      {"geomId", "crt_element"},           {"rayxId", "gl_LaunchIDEXT.x"},     {"rayyId", "gl_LaunchIDEXT.y"}};
  std::string out;
  for (auto* f : info->fields()) {
    auto known = builtins.find(f->getNameAsString());
    out += "  " + var + "." + KernelPrinter::SafeName(f->getNameAsString()) + " = " + (known != builtins.end() ? known->second : ZeroOf(f->getType())) + ";\n";
  }
  return out;
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

// The composed implementation's public `std::vector<CRT_AABB> LeafBoxes(<integer>) const`, which gives
// an element's leaf boxes on the host (the paper's form), or null.
const CXXMethodDecl* LeafBoxesMethod(const CXXRecordDecl* impl) {
  for (auto* d : impl->lookup(&impl->getASTContext().Idents.get("LeafBoxes")))
    if (auto* md = dyn_cast<CXXMethodDecl>(d); md && md->isConst() && md->getAccess() == AS_public && md->getNumParams() == 1 &&
                                                md->getParamDecl(0)->getType()->isIntegerType()) {
      QualType element;
      auto* box = IsStdVector(md->getReturnType(), &element) ? element->getAsCXXRecordDecl() : nullptr;
      if (box && box->getName() == "CRT_AABB") return md;
    }
  return nullptr;
}

// One leaf call of a composed traversal, in one of two forms:
//   for (...) if (<box test>) m_shapes[i]->Intersect(posAndNear, dirAndFar, i, hit);
//   while (<walk>) { ... m_geom[info.geomId]->Intersect(posAndNear, dirAndFar, info, hit, this); ... }
// The ray tracing hardware can run the loop when the call has the fixed form the paper gives
// Intersect: the ray (two float4: origin and near, direction and far) first, then the hit (a struct
// whose first field is its distance, updated when the leaf is nearer) and the leaf's index,
// constants, or (the second form) the CRT_LeafInfo and the traversal itself. In the second form the
// hardware walks each element's LeafBoxes. Then `hardware` prints a trace where the loop was; the call's site
// (its vector and method, shared by other calls of both) joins `sites`, and its intersection,
// closest-hit and miss shaders join `shaders`. Returns why not, or "".
std::string TraceLeafCall(ASTContext& ctx, Reporter& rep, const ClassModel& model, const Composition& comp, const CXXRecordDecl* implClass,
                          const std::string& kernel, const CXXMemberCallExpr* call, KernelPrinter& hardware, std::vector<LeafTraversal>& sites, std::vector<GlslDecl>& payloads,
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
  // Two forms. The paper's (listing 2): a CRT_LeafInfo among the arguments, the call anywhere in the
  // traversal's loop, whose whole walk the hardware does over each element's leaf boxes. Or a loop
  // over all leaves, one per element, `for (T i = 0; i < count; ++i) [if (box test)] call;`.
  const unsigned n = method->getNumParams();
  int infoIndex = -1;
  for (unsigned i = 0; i < n; ++i)
    if (auto* rd = method->getParamDecl(i)->getType().getNonReferenceType()->getAsCXXRecordDecl(); rd && rd->getName() == "CRT_LeafInfo") infoIndex = int(i);
  const bool paperForm = infoIndex >= 0;
  const VarDecl* loopVar = paperForm ? nullptr : LeafLoopVariable(ctx, leaf.loop, call);
  if (!paperForm && !loopVar)
    return "the loop calling " + callText + " (" + site + ") is not 'for (i = 0; i < count; ++i) [if (box test)] " + method->getNameAsString() +
           "(...);', which visits every leaf once as the hardware does, and the call passes no CRT_LeafInfo (the paper's form, whose traversal the hardware replaces)";
  LoopEffects effects(call);
  effects.TraverseStmt(const_cast<clang::Stmt*>(leaf.loop));
  if (!paperForm && !effects.problem.empty())
    return "the loop calling " + callText + " does more than visit leaves: " + effects.problem + " (" + at(effects.where) + ")";

  // The call's form: (float4 ray origin and near, float4 direction and far, ..., Hit& hit, ...): the
  // hit is the last parameter, or in the paper's form the one written back that is not the info.
  auto isFloat4 = [](QualType t) { return GlslTypeOf(t.getNonReferenceType().getUnqualifiedType()).value_or("") == "vec4"; };
  int hitIndex = paperForm ? -1 : int(n) - 1;
  for (unsigned i = 2; paperForm && i < n; ++i)
    if (int(i) != infoIndex && WrittenBack(method, i) && method->getParamDecl(i)->getType().getNonReferenceType()->isRecordType()) hitIndex = int(i);
  const QualType hitParam = hitIndex >= 0 ? method->getParamDecl(unsigned(hitIndex))->getType() : QualType();
  const auto* hitRecord = hitIndex >= 0 ? hitParam.getNonReferenceType()->getAsCXXRecordDecl() : nullptr;
  const std::string form = paperForm ? "(float4 posAndNear, float4 dirAndFar, CRT_LeafInfo info, Hit& hit, [const Traversal* or constants])"
                                     : "(float4 posAndNear, float4 dirAndFar, [leaf index or constants,] Hit& hit)";
  if (n < 3 || !isFloat4(method->getParamDecl(0)->getType()) || !isFloat4(method->getParamDecl(1)->getType()) || hitIndex < 0 ||
      !WrittenBack(method, unsigned(hitIndex)) || !hitRecord || hitRecord->isPolymorphic() || !method->getReturnType()->isVoidType())
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
    zeroHit += "  hit." + KernelPrinter::SafeName(f->getNameAsString()) + " = " + zero + ";\n";
  }
  // Arguments: the ray and the hit as the traversal has them before the loop; the index as the leaf.
  if (!paperForm && NamedVar(indexExpr) != loopVar)
    return callText + " picks its object with an expression, not the loop's variable: the hardware names a leaf by its element's position";
  auto outer = [&](const clang::Expr* e) {
    const VarDecl* vd = NamedVar(e);
    return vd && vd->isLocalVarDeclOrParm() && !effects.inner.count(vd) ? vd : nullptr;
  };
  const VarDecl* hitVar = outer(call->getArg(unsigned(hitIndex)));
  if (!outer(call->getArg(0)) || !outer(call->getArg(1)) || !hitVar)
    return "the ray and the hit " + callText + " takes must be variables of the traversal declared before the loop";
  // The paper's form: what the walk computes besides the hit is the hardware's, and no use of it may follow.
  for (auto& [vd, loc] : effects.outerWrites)
    if (paperForm && vd != hitVar && UsedAfter(leaf.fn, leaf.loop, vd))
      return "the traversal's loop writes '" + vd->getNameAsString() + "' (" + at(loc) + "), read after it: the hardware's walk gives only the hit";
  // The other arguments, in the intersection shader: the leaf's index is its instance's (one instance
  // per element, in order); the info is the hardware's; the traversal itself (`this`) is left out.
  GlslPrinter literals(ctx, implClass, rep);
  std::vector<std::string> args;
  for (unsigned i = 0; i < n; ++i) {
    const clang::Expr* arg = call->getArg(i)->IgnoreParenImpCasts();
    auto type = GlslTypeOf(method->getParamDecl(i)->getType().getNonReferenceType().getUnqualifiedType());
    if (i == 0) args.push_back(paperForm ? "vec4(gl_ObjectRayOriginEXT, gl_RayTminEXT)" : "vec4(gl_WorldRayOriginEXT, gl_RayTminEXT)");
    else if (i == 1) args.push_back(paperForm ? "vec4(gl_ObjectRayDirectionEXT, gl_RayTmaxEXT)" : "vec4(gl_WorldRayDirectionEXT, gl_RayTmaxEXT)");
    else if (int(i) == infoIndex) args.push_back("crt_info");
    else if (int(i) == hitIndex) args.push_back("hit");
    else if (KernelPrinter::PointsTo(method->getParamDecl(i)->getType(), implClass) && isa<CXXThisExpr>(arg)) continue;
    else if (!paperForm && NamedVar(arg) == loopVar && type) args.push_back(*type + "(gl_InstanceID)");
    else if (isa<IntegerLiteral, FloatingLiteral, CXXBoolLiteralExpr>(arg) && type) args.push_back(*type + "(" + literals.Expr(arg) + ")");
    else return "argument " + std::to_string(i + 1) + " of " + callText + " is neither " + (paperForm ? "`this`" : "the leaf's index") + " nor a constant";
  }
  QualType element;
  IsStdVector(field->getType(), &element);
  const CXXRecordDecl* interface = PolymorphicPointee(element);  // the elements' (the method may be a base's)
  if (paperForm && !LeafBoxesMethod(implClass))
    return comp.implName + " declares no public 'std::vector<CRT_AABB> LeafBoxes(uint32_t geomId) const': the hardware needs the boxes of each element of " +
           vm->display + " (its leaves, in the order of CRT_LeafInfo::aabbId)";
  if (!paperForm && (!BoxCorner(interface, "BoxMin") || !BoxCorner(interface, "BoxMax")))
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
    if (paperForm) lt.leafBoxes = "crt_" + comp.holder + "()->LeafBoxes";
    lt.missIndex = unsigned(sites.size());
    for (auto& s : sites) lt.firstHitGroup += unsigned(s.intersectionShaders.size());
    if (lt.firstHitGroup > 15)
      return "the leaf calls before " + callText + " (" + site + ") have " + std::to_string(lt.firstHitGroup) +
             " classes; a trace can skip at most 15 hit groups (traceRayEXT's SBT record offset has 4 bits)";
  } else {
    lt = *known;
  }
  const std::string payload = member + "_" + methodName + "_hit", scene = member + "_leaves";
  const std::string p = hardware.Expr(call->getArg(0)), d = hardware.Expr(call->getArg(1)), h = hardware.Expr(call->getArg(unsigned(hitIndex)));
  const std::string t = h + "." + KernelPrinter::SafeName(distance->getNameAsString()), number = std::to_string(lt.missIndex);
  // The trace (templates/glsl/leaf_trace.glsl.mustache) stands where the loop was.
  Data trace;
  trace.set("traversal", comp.implName + "::" + leaf.fn->getNameAsString());
  trace.set("callText", callText);
  trace.set("site", site);
  trace.set("method", methodName);
  trace.set("origin", p);
  trace.set("direction", d);
  trace.set("hit", h);
  trace.set("distance", t);
  trace.set("payload", payload);
  trace.set("scene", scene);
  trace.set("missIndex", number);
  trace.set("hitGroupOffset", std::to_string(lt.firstHitGroup));
  if (lt.firstHitGroup) trace.set("firstHitGroup", std::to_string(lt.firstHitGroup));
  else trace.set("firstHitGroup", false);
  hardware.replacedStatements[leaf.loop] = Render(model.templateDir + "/glsl/leaf_trace.glsl.mustache", trace);
  const std::string hitType = *hardware.Type(hitParam.getNonReferenceType().getUnqualifiedType(), call->getBeginLoc());
  if (fresh)
    payloads.push_back({payload, "// The hit the leaves' intersection shaders report to ('" + hitVar->getNameAsString() + "', passed to " + callText + ")\nlayout(location = " +
                                     number + ") rayPayloadEXT " + hitType + " " + payload + ";\n"});

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
    GlslPrinter object(ctx, *impl, rep);
    object.selfClass = *impl;
    object.composedPrefix = vi.name + "_";
    GlslPrinter traversal(ctx, implClass, rep);  // what the object reads through `this` of the traversal
    traversal.composedPrefix = hardware.composedPrefix;
    object.owner = &traversal;
    for (auto& sn : ClassStructNames(model)) object.predeclaredStructs.insert(sn);
    const std::string function = ImplementationMethod(rep, object, *impl, method, call->getBeginLoc());
    if (function.empty()) return "the GPU has no body of " + vi.name + "::" + methodName;  // reported
    object.Type(hitParam.getNonReferenceType().getUnqualifiedType(), call->getBeginLoc());
    StageShader s;
    for (auto* f : traversal.Uses().memberVectors) s.buffers.push_back(hardware.composedPrefix + f->getNameAsString());
    // Bound as its kernel binds them: a shader reading the traversal's buffers is the kernel's own.
    const std::string name = (s.buffers.empty() ? "" : kernel + "_") + member + "_" + vi.name + "_" + methodName;
    if (!s.buffers.empty()) s.kernel = kernel;
    lt.intersectionShaders.push_back(name);
    s.name = name;
    s.stage = "rint";
    s.origin = vi.name + "::" + methodName;
    s.description = "what " + callText + " runs for a leaf that is a " + vi.name + ",\n// as the intersection shader of the ray tracing pipelines tracing " +
                    vm->display + "'s leaves (virtual functions, level 3)";
    s.scalarLayout = vi.scalarLayout;
    s.classData = true;
    for (auto& x : object.Constants()) s.constants += x.text;
    for (auto& x : object.Structs()) s.structs += x.text + "\n";
    s.structs += TagsReference(model, *vm).text + "\n" + ImplDataStruct(model, object, *impl, *vm, vi).text + "\n" + ObjectsReference(model, *vm, vi).text + "\n" +
                 "hitAttributeEXT " + hitType + " crt_hit;  // what the closest-hit shader receives\n";
    for (auto& x : object.Functions()) s.functions += x + "\n";
    std::string callArgs = "self";
    for (auto& a : args) callArgs += ", " + a;
    const std::string dist = KernelPrinter::SafeName(distance->getNameAsString());
    std::string leafInfo;
    if (paperForm) {
      const auto* info = method->getParamDecl(unsigned(infoIndex))->getType().getNonReferenceType()->getAsCXXRecordDecl();
      leafInfo = "  // What the traversal would tell the leaf: its box, the instance, the element (geometry), the ray.\n  " + *object.Type(QualType(info->getTypeForDecl(), 0), call->getBeginLoc()) +
                 " crt_info;\n" + LeafInfoFrom(info, "crt_info");
    }
    s.mainBody = (paperForm ? "  // The leaf is box gl_PrimitiveID of element gl_InstanceCustomIndexEXT of " + vm->display +
                                  " (an instance per element over its LeafBoxes).\n  const uint crt_element = uint(gl_InstanceCustomIndexEXT);\n"
                            : "  // The leaf is element gl_InstanceID of " + vm->display + " (one instance per element, in order).\n") +
                 "  const uvec2 tag = " + member + "_Tags(" + generated::VirtualTagsField(member) + ").tags[" + (paperForm ? "crt_element" : "gl_InstanceID") + "];\n"
                 "  const " + vi.name + "_Data self = " + member + "_" + vi.name + "Objects(" + generated::VirtualClassField(member, vi.name) + ").objects[tag.y];\n" + leafInfo +
                 "  // Nearer than the ray's end (the nearest hit so far) or nothing: the other fields start at zero.\n"
                 "  " + hitType + " hit;\n" + zeroHit + "  hit." + dist + " = gl_RayTmaxEXT;\n"
                 "  " + function + "(" + callArgs + ");\n"
                 "  if (hit." + dist + " < gl_RayTmaxEXT)\n  {\n    crt_hit = hit;\n"
                 "    reportIntersectionEXT(hit." + dist + ", 0u);\n  }\n";
    if (!addShader(s)) return "another leaf call of " + callText + " passes other arguments (" + site + ")";
  }
  // The closest-hit shader hands the nearest leaf's hit to the trace; the miss shader leaves it.
  lt.closestHitShader = member + "_" + methodName + "_Hit";
  lt.missShader = member + "_" + methodName + "_Miss";
  std::string hitStructs;
  for (auto& x : hardware.Structs()) hitStructs += x.text + "\n";
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

}  // namespace

void AnalyzeLeafTraversal(ASTContext& ctx, Reporter& rep, ClassModel& model, Kernel& k, const Composition& comp, const CXXRecordDecl* implClass,
                          const std::string& holderPrefix, const KernelPrinter& printer) {
  if (std::any_of(k.composedCalls.begin(), k.composedCalls.end(), [&](const auto& c) { return c.first != comp.holder; })) {
    k.whyNoLeafShaders = "it calls code composed through more than one member";
    return;
  }
  // The traversal again, with each leaves' loop replaced by a trace (the leaves' code is left out).
  GlslPrinter hardware(ctx, implClass, rep);
  hardware.composedPrefix = holderPrefix;
  for (auto& sn : ClassStructNames(model)) hardware.predeclaredStructs.insert(sn);
  std::vector<LeafTraversal> sites;
  std::vector<GlslDecl> payloads;
  std::vector<StageShader> shaders;
  for (const CXXMemberCallExpr* call : printer.Uses().virtualCallSites)
    if (std::string why = TraceLeafCall(ctx, rep, model, comp, implClass, k.name, call, hardware, sites, payloads, shaders); !why.empty()) {
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

}  // namespace crossrt::engine
