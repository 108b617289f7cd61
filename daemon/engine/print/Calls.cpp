// The printer's calls: user functions (printed once, callees first), LiteMath and <cmath> built-ins,
// numeric limits, crossrt::Atomic* and LiteMath's InterlockedAdd family, and what kernels may not
// call (I/O, the heap). Part of KernelPrinter (KernelPrinter.h); each language's
// library calls are its printer's (glsl/GlslCalls.cpp, ispc/IspcCalls.cpp).
#include "print/KernelPrinter.h"
#include "generate/GeneratedNames.h"
#include "analyse/AstQueries.h"
#include "print/PrinterParts.h"

#include <clang/AST/RecordLayout.h>
#include <clang/Basic/SourceManager.h>
#include <clang/Lex/Lexer.h>

#include <cstdio>
#include <map>
#include <set>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

namespace {
bool IsIoFunction(const std::string& n) {
  static const std::set<std::string> io = {"printf", "fprintf", "puts", "fputs", "putchar", "fopen", "fclose",
      "fread", "fwrite", "fscanf", "scanf", "sprintf", "snprintf", "fflush", "perror", "getchar"};
  return io.count(n) > 0;
}
bool IsHeapFunction(const std::string& n) {
  return n == "malloc" || n == "calloc" || n == "realloc" || n == "free" || n == "aligned_alloc";
}

// std::numeric_limits<float, int or uint>::infinity(), max() and the like as constant expressions,
// which global constants need; infinity and NaN as the language spells them (`infinity`, `nan`:
// neither language has a literal for them). Empty for anything else.
std::string NumericLimit(const FunctionDecl* fd, const std::string& infinity, const std::string& nan) {
  auto* spec = dyn_cast_or_null<ClassTemplateSpecializationDecl>(fd->getDeclContext());
  if (!spec || spec->getName() != "numeric_limits" || !spec->isInStdNamespace() || spec->getTemplateArgs().size() != 1)
    return "";
  const QualType t = spec->getTemplateArgs()[0].getAsType().getCanonicalType();
  const std::string n = fd->getNameAsString();
  if (t->isSpecificBuiltinType(BuiltinType::Float)) {
    if (n == "infinity") return infinity;
    if (n == "quiet_NaN") return nan;
    // Nine significant digits: each literal rounds to exactly the float it names.
    static const std::map<std::string, std::string> values = {
        {"max", "3.40282347e+38"},
        {"lowest", "-3.40282347e+38"},    {"min", "1.17549435e-38"},    {"epsilon", "1.1920929e-07"},
        {"denorm_min", "1.40129846e-45"}};
    auto it = values.find(n);
    return it == values.end() ? "" : it->second;
  }
  if (t->isSpecificBuiltinType(BuiltinType::Int)) {
    if (n == "max") return "0x7FFFFFFF";
    if (n == "min" || n == "lowest") return "(-2147483647 - 1)";
  }
  if (t->isSpecificBuiltinType(BuiltinType::UInt)) {
    if (n == "max") return "0xFFFFFFFFu";
    if (n == "min" || n == "lowest") return "0u";
  }
  return "";
}
}  // namespace

std::string CallText(const std::string& f, const std::vector<std::string>& args) {
  std::string s = f + "(";
  for (size_t i = 0; i < args.size(); ++i) s += (i ? ", " : "") + args[i];
  return s + ")";
}

// Library functions with a counterpart in the kernel's language: LiteMath, <cmath>, std::min/max,
// std::numeric_limits (the limits and the bit builtins here, the rest by the language: LibraryCall).
std::string KernelPrinter::Builtin(const FunctionDecl* fd, const std::vector<std::string>& a, const CallExpr* call) {
  std::string n = fd->getNameAsString();
  if (std::string limit = NumericLimit(fd, FloatInfinity(), FloatNaN()); !limit.empty()) return limit;
  // The functions each language spells as GLSL does (LibraryCall gets them).
  static const std::map<std::string, std::string> same = {
      {"sqrt", "sqrt"}, {"sqrtf", "sqrt"}, {"abs", "abs"}, {"fabs", "abs"}, {"fabsf", "abs"},
      {"min", "min"}, {"max", "max"}, {"fmin", "min"}, {"fminf", "min"}, {"fmax", "max"}, {"fmaxf", "max"},
      {"clamp", "clamp"}, {"pow", "pow"}, {"powf", "pow"}, {"exp", "exp"}, {"expf", "exp"},
      {"exp2", "exp2"}, {"exp2f", "exp2"}, {"log", "log"}, {"logf", "log"}, {"log2", "log2"}, {"log2f", "log2"},
      {"sin", "sin"}, {"sinf", "sin"}, {"cos", "cos"}, {"cosf", "cos"}, {"tan", "tan"}, {"tanf", "tan"},
      {"asin", "asin"}, {"asinf", "asin"}, {"acos", "acos"}, {"acosf", "acos"}, {"atan", "atan"}, {"atanf", "atan"},
      {"sinh", "sinh"}, {"sinhf", "sinh"}, {"cosh", "cosh"}, {"coshf", "cosh"}, {"tanh", "tanh"}, {"tanhf", "tanh"},
      {"asinh", "asinh"}, {"asinhf", "asinh"}, {"acosh", "acosh"}, {"acoshf", "acosh"}, {"atanh", "atanh"}, {"atanhf", "atanh"},
      {"atan2", "atan"}, {"atan2f", "atan"}, {"floor", "floor"}, {"floorf", "floor"}, {"ceil", "ceil"},
      {"ceilf", "ceil"}, {"trunc", "trunc"}, {"truncf", "trunc"},
      {"fract", "fract"}, {"sign", "sign"}, {"dot", "dot"}, {"cross", "cross"}, {"length", "length"},
      {"normalize", "normalize"}, {"distance", "distance"}, {"reflect", "reflect"}, {"refract", "refract"},
      {"mix", "mix"}, {"lerp", "mix"}, {"step", "step"}, {"smoothstep", "smoothstep"},
      {"inversesqrt", "inversesqrt"}, {"transpose", "transpose"}, {"inverse", "inverse"},
      {"inverse4x4", "inverse"}, {"isnan", "isnan"}, {"isinf", "isinf"}, {"fma", "fma"}, {"fmaf", "fma"},
      {"make_float2", "vec2"}, {"make_float3", "vec3"}, {"make_float4", "vec4"}, {"make_int2", "ivec2"},
      {"make_int3", "ivec3"}, {"make_int4", "ivec4"}, {"make_uint2", "uvec2"}, {"make_uint3", "uvec3"},
      {"make_uint4", "uvec4"}, {"to_float2", "vec2"}, {"to_int2", "ivec2"}, {"to_int3", "ivec3"},
      {"to_int4", "ivec4"}, {"to_uint2", "uvec2"}, {"to_uint3", "uvec3"}, {"to_uint4", "uvec4"},
      {"to_float4", "vec4"}, {"mod", "mod"}, {"faceforward", "faceforward"}, {"outerProduct", "outerProduct"},
      {"determinant", "determinant"}, {"inverse3x3", "inverse"}};
  // GCC/Clang bit builtins (C++ leaves clz and ctz of 0 undefined).
  if (fd->getBuiltinID() != 0) {
    const std::string u = BitArgument(a[0], call->getArg(0));
    if (n == "__builtin_clz") return "(31 - findMSB(" + u + "))";
    if (n == "__builtin_ctz") return "findLSB(" + u + ")";
    if (n == "__builtin_popcount") return "bitCount(" + u + ")";
  }
  bool library = IsSystemDecl(fd) || InNamespace(fd, "LiteMath");
  if (!library) return "";
  return LibraryCall(fd, a, call, same);
}

// ---- crossrt::GangSize, AnyLane, ... (Gang.h): each language's GangCall ----

bool IsGangFunction(const FunctionDecl* fd) {
  static const std::set<std::string> names = {"GangSize", "AnyLane", "AllLanes", "FirstLane", "MinOverLanes", "AllLanesOn",
                                                "LaneIndex", "LaneBits", "LaneValue", "LaneOf", "LaneOfQuad", "FromLane"};
  return fd && InNamespace(fd, "crossrt") && names.count(fd->getNameAsString()) > 0;
}

// Folded where it decides alone: `GangSize() > 1 && rest` is false with a gang of one, whatever the
// rest; comparisons of GangSize() with a constant, !, && and ||. GangSize() itself has no effect.
std::optional<bool> KernelPrinter::GangCondition(const clang::Expr* e) const {
  const std::optional<int> size = FixedGangSize();
  if (!size) return std::nullopt;
  e = e->IgnoreParenImpCasts();
  auto value = [&](const clang::Expr* side) -> std::optional<int64_t> {
    side = side->IgnoreParenImpCasts();
    if (auto* call = dyn_cast<CallExpr>(side); call && IsGangFunction(call->getDirectCallee()) && call->getDirectCallee()->getName() == "GangSize")
      return *size;
    clang::Expr::EvalResult r;
    if (!side->isValueDependent() && side->EvaluateAsInt(r, m_ctx)) return r.Val.getInt().getExtValue();
    return std::nullopt;
  };
  if (auto* u = dyn_cast<UnaryOperator>(e); u && u->getOpcode() == UO_LNot) {
    auto inner = GangCondition(u->getSubExpr());
    return inner ? std::optional<bool>(!*inner) : std::nullopt;
  }
  auto* bo = dyn_cast<BinaryOperator>(e);
  if (!bo) return std::nullopt;
  if (bo->getOpcode() == BO_LAnd || bo->getOpcode() == BO_LOr) {
    // As C++ evaluates them: where the left side decides, the right is never evaluated; where the
    // right side does, the left is, so it may be left out only where it has no effect.
    const bool decides = bo->getOpcode() == BO_LOr;  // the value of one side that decides the whole
    auto l = GangCondition(bo->getLHS());
    if (l) return *l == decides ? std::optional<bool>(decides) : GangCondition(bo->getRHS());
    auto r = GangCondition(bo->getRHS());
    if (r && *r == decides && !bo->getLHS()->HasSideEffects(m_ctx)) return decides;
    return std::nullopt;
  }
  if (!bo->isComparisonOp()) return std::nullopt;
  const bool onGang = [&] {
    for (const clang::Expr* side : {bo->getLHS(), bo->getRHS()})
      if (auto* call = dyn_cast<CallExpr>(side->IgnoreParenImpCasts()); call && IsGangFunction(call->getDirectCallee()))
        return true;
    return false;
  }();
  auto l = value(bo->getLHS()), r = value(bo->getRHS());
  if (!onGang || !l || !r) return std::nullopt;
  switch (bo->getOpcode()) {
    case BO_EQ: return *l == *r;
    case BO_NE: return *l != *r;
    case BO_LT: return *l < *r;
    case BO_GT: return *l > *r;
    case BO_LE: return *l <= *r;
    case BO_GE: return *l >= *r;
    default: return std::nullopt;
  }
}

// An if's condition: `GangSize() == 1 && rest` (or `rest && ...`) where the gang's term holds in
// this language's gang is printed as `rest` alone, as a gang of one evaluates it.
std::string KernelPrinter::IfCondition(const clang::Expr* cond) {
  if (auto* bo = dyn_cast<BinaryOperator>(cond->IgnoreParenImpCasts()); bo && bo->getOpcode() == BO_LAnd) {
    if (auto l = GangCondition(bo->getLHS()); l && *l) return IfCondition(bo->getRHS());
    if (auto r = GangCondition(bo->getRHS()); r && *r) return IfCondition(bo->getLHS());
  }
  return Expr(cond);
}

bool IsUniformLocal(const VarDecl* vd) {
  if (!vd || !vd->isLocalVarDecl()) return false;
  for (const auto* a : vd->specific_attrs<AnnotateAttr>())
    if (a->getAnnotation() == "crossrt::uniform") return true;
  return false;
}

bool IsSpecializedMember(const FieldDecl* field) {
  if (!field) return false;
  for (const auto* a : field->specific_attrs<AnnotateAttr>())
    if (a->getAnnotation() == "crossrt::specialize") return true;
  return false;
}

// ---- crossrt::Atomic* (Atomics.h): GLSL atomics between buffer memory barriers ----

bool IsCrossrtAtomic(const FunctionDecl* fd) {
  static const std::set<std::string> names = {"AtomicAdd", "AtomicAnd", "AtomicOr", "AtomicXor", "AtomicExchange",
                                              "AtomicMin", "AtomicMax", "AtomicCompareExchange"};
  return fd && InNamespace(fd, "crossrt") && names.count(fd->getNameAsString()) > 0;
}

// GLSL atomics take a buffer (or shared) variable itself, never a copy: the target must be a
// path of indexing and field selection from a buffer the kernel binds. Empty when it is.
std::string KernelPrinter::AtomicTargetProblem(const clang::Expr* e) const {
  while (true) {
    e = e->IgnoreParenImpCasts();
    if (auto* me = dyn_cast<MemberExpr>(e)) {
      const clang::Expr* base = me->getBase()->IgnoreParenImpCasts();
      if (isa<CXXThisExpr>(base)) {
        if (selfClass) return "it is a member of an object reached through a virtual call, which kernels only read";
        if (IsImage2D(me->getType())) return "it is a texel of an image";
        return "";  // a data member (the class-data block) or an element of a member vector
      }
      if (me->isArrow()) {  // p->field: p must be a kernel's pointer parameter
        e = base;
        break;
      }
      e = base;
      continue;
    }
    if (auto* op = dyn_cast<CXXOperatorCallExpr>(e); op && op->getOperator() == OO_Subscript) {
      if (!IsStdVector(op->getArg(0)->getType())) return "it is an element of a container kernels cannot index atomically";
      e = op->getArg(0);
      continue;
    }
    if (auto* as = dyn_cast<ArraySubscriptExpr>(e)) {
      const clang::Expr* base = as->getBase()->IgnoreParenImpCasts();
      if (base->getType()->isPointerType()) {
        e = base;
        break;
      }
      e = base;  // a fixed-size array inside an element
      continue;
    }
    if (auto* uo = dyn_cast<UnaryOperator>(e); uo && uo->getOpcode() == UO_Deref) {
      e = uo->getSubExpr()->IgnoreParenImpCasts();
      break;
    }
    break;
  }
  // What remains names the root: a pointer parameter of the kernel is a buffer, anything else a copy.
  auto* dr = dyn_cast<DeclRefExpr>(e);
  auto* param = dr ? dyn_cast<ParmVarDecl>(dr->getDecl()) : nullptr;
  if (param && param->getType()->isPointerType()) {
    if (valueParams.count(param)) return "parameter '" + param->getNameAsString() + "' holds one value per thread (a local of the control function's thread loop)";
    return "";
  }
  if (param && param->getType()->isReferenceType())
    return "reference parameter '" + param->getNameAsString() + "' is a copy on the GPU (GLSL passes it in and out)";
  if (dr) return "'" + dr->getDecl()->getNameAsString() + "' is a local variable, private to each GPU thread";
  return "it is not a variable in device memory";
}

std::string KernelPrinter::AtomicCall(const FunctionDecl* fd, const CallExpr* call) {
  const std::string name = fd->getNameAsString();
  if (std::string problem = AtomicTargetProblem(call->getArg(0)); !problem.empty())
    return Fail(call->getArg(0)->getExprLoc(), "the target of crossrt::" + name + " is not in device memory: " + problem,
                "make the target an element of a std::vector member, a data member, or an element of a kernel's pointer parameter");
  m_uses.atomics = true;
  std::vector<std::string> args;
  for (auto* arg : call->arguments()) args.push_back(Expr(arg));
  return AtomicOperation(name, args);
}
std::string KernelPrinter::Call(const CallExpr* call) {
  const FunctionDecl* fd = call->getDirectCallee();
  if (!fd) return Fail(call->getBeginLoc(), "indirect call in a kernel", "call functions directly; lambdas and function pointers are not supported");
  std::string name = fd->getNameAsString();
  std::string qname = fd->getQualifiedNameAsString();

  // Members of the user's class: helpers become GLSL functions.
  if (auto* mc = dyn_cast<CXXMemberCallExpr>(call)) {
    const clang::Expr* obj = mc->getImplicitObjectArgument()->IgnoreParenImpCasts();
    auto* method = mc->getMethodDecl();
    if (isa<CXXThisExpr>(obj) && m_structSelf) {  // another member function of the struct being printed
      std::map<unsigned, std::string> bindings;
      std::vector<std::string> args = HelperArgs(method, call, bindings);
      std::string s = EmitHelper(method, call->getBeginLoc(), false, bindings, m_structSelf) + "(self";
      for (auto& a : args) s += ", " + a;
      return s + ")";
    }
    if (isa<CXXThisExpr>(obj)) {
      if (StringRef(name).starts_with("kernel"))
        return Fail(call->getBeginLoc(), "kernel '" + name + "' is called from inside a kernel", "call kernels only from control functions");
      std::vector<std::string> args;
      if (std::string data = ClassDataArgument(); !data.empty() && !selfClass && !method->isStatic()) args.push_back(data);  // the class's data, as kernels have it
      if (selfClass) {
        args.push_back("self");
        // The object's exact class is known: a virtual call on it is static.
        if (auto* overrider = method->getCorrespondingMethodInClass(selfClass); overrider && method->isVirtual()) {
          for (auto* arg : call->arguments()) args.push_back(Expr(arg));
          std::string s = EmitHelper(overrider, call->getBeginLoc(), true) + "(";
          for (size_t i = 0; i < args.size(); ++i) s += (i ? ", " : "") + args[i];
          return s + ")";
        }
      }
      std::map<unsigned, std::string> bindings;
      for (auto& a : HelperArgs(method, call, bindings)) args.push_back(a);
      // In composed code, the implementation is the one COMPOSE names: a virtual method it calls on
      // itself is its own (AnyHit calling NearestHit), as the GPU has no other.
      const CXXMethodDecl* own = !selfClass && !composedPrefix.empty() && method->isVirtual() ? method->getCorrespondingMethodInClass(m_class) : nullptr;
      std::string callee = own ? EmitHelper(own, call->getBeginLoc(), true, bindings) : EmitHelper(method, call->getBeginLoc(), false, bindings);
      std::string s = callee + "(";
      for (size_t i = 0; i < args.size(); ++i) s += (i ? ", " : "") + args[i];
      return s + ")";
    }
    // Calls on an Image2D member or parameter: texel loads and stores, samples, its size.
    if (auto* image = ImageOf(obj)) return ImageCall(image, mc);
    // Calls on a texture of an array of textures.
    const clang::Expr* textureIndex = nullptr;
    if (auto* array = TextureElement(obj, &textureIndex))
      return TextureCall(array, textureIndex, mc);
    // Calls of the traversal passed to an object's method: scene->Helper(...).
    if (OwnerParamOf(obj)) return OwnerCall(mc);
    // Calls through a member holding an interface: composition.
    std::string composed = ComposedCall(mc);
    if (!composed.empty()) return composed;
    // Calls through an element of a vector of objects: dynamic dispatch.
    std::string dispatched = VirtualCall(mc);
    if (!dispatched.empty()) return dispatched;
    // Calls on a std::vector member.
    if (auto* me = dyn_cast<MemberExpr>(obj); me && IsStdVector(me->getType())) {
      auto* field = dyn_cast<FieldDecl>(me->getMemberDecl());
      if (field && isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts()) && IsTextureArray(field->getType())) {
        if (name == "size" && UsableTextures(field, call->getBeginLoc())) return MemberAccess(generated::SizeField(field->getNameAsString()));
        return Fail(call->getBeginLoc(), "std::vector::" + name + " of an array of textures in a kernel",
                    "kernels read its size() and use its textures: " + field->getNameAsString() + "[i].sample(uv)");
      }
      QualType element;
      if (field && isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts()) && name == "size" && IsStdVector(field->getType(), &element) &&
          PolymorphicPointee(element)) {
        m_uses.objectSizeReads.emplace(field, call->getBeginLoc());
        return MemberAccess(generated::SizeField(field->getNameAsString()));
      }
      if (field && isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts())) {
        m_uses.memberVectors.insert(field);
        if (name == "size" || name == "empty") {
          m_uses.sizeReads.emplace(field, call->getBeginLoc());
          const std::string size = MemberAccess(generated::SizeField(field->getNameAsString()));
          return name == "size" ? size : EmptyTest(size);
        }
        if (name == "capacity") return MemberAccess(generated::CapacityField(field->getNameAsString()));
        if (std::string handled = VectorMethod(field, mc, name); !handled.empty()) return handled;
        // Emptied by the one thread before a loop nest: the appends that follow count from 0.
        const bool empties = name == "clear" || (name == "resize" && call->getNumArgs() == 1 && call->getArg(0)->isIntegerConstantExpr(m_ctx) &&
                                                  call->getArg(0)->EvaluateKnownConstInt(m_ctx) == 0);
        if (empties && singleThread && composedPrefix.empty()) {
          m_uses.emptiedVectors.insert(field);
          return generated::SizeField(field->getNameAsString()) + " = 0u";
        }
        if (name == "push_back" && call->getNumArgs() == 1 && composedPrefix.empty())
          return EmitAppend(field, call) + "(" + Expr(call->getArg(0)) + ")";
      }
      return Fail(call->getBeginLoc(), "std::vector::" + name + " is not supported in kernels",
                  "kernels may index member vectors, call size() and capacity(), and push_back() to a member vector");
    }
    // std::array<T, N>, held as T[N]: its size is N.
    if (uint64_t n = 0; IsStdArray(obj->getType(), nullptr, &n) && (name == "size" || name == "max_size") && call->getNumArgs() == 0)
      return SizeLiteral(n);
    // Member functions of plain structs (the user's, LiteMath's complex and Box4f) and of matrices.
    if (IsPlainStruct(method->getParent())) return StructMethodCall(mc);
    if (IsLiteMathType(obj->getType(), "float4x4") || IsLiteMathType(obj->getType(), "float3x3")) return MatrixMethodCall(mc);
    if (IsStdVector(obj->getType().getNonReferenceType()))  // a vector passed to a helper, or a local one
      return Fail(call->getBeginLoc(), "call to '" + qname + "' on a std::vector that is not a data member, in a kernel",
                  "kernels reach vectors through the class's members: make the helper a member function that reads the member itself");
    if (IsSystemDecl(method) || method->getParent()->isInStdNamespace())
      return Fail(call->getBeginLoc(), "call to '" + qname + "' is not supported in a kernel",
                  "kernels may call LiteMath, <cmath> and std::min/max, and your own functions");
    return Fail(call->getBeginLoc(), "member function call '" + qname + "' on an object is not supported in kernels",
                "make it a free function or a member of the class that takes the object as a parameter");
  }

  if (IsHeapFunction(name))
    return Fail(call->getBeginLoc(), "heap allocation ('" + name + "') in a kernel",
                "GPU threads cannot allocate: use a fixed-size local array or a std::vector member sized before the call");
  if (IsIoFunction(name))
    return Fail(call->getBeginLoc(), "I/O ('" + name + "') in a kernel",
                "kernels cannot do I/O: write results to an output buffer and print them in the control function");

  const bool interlocked = InNamespace(fd, "LiteMath") && (name == "InterlockedAdd" || name == "atomicAdd" || name == "InterlockedAdd3f" || name == "ReduceAdd");
  if (interlocked) return InterlockedCall(fd, call);
  if (IsCrossrtAtomic(fd)) return AtomicCall(fd, call);
  if (IsGangFunction(fd)) return GangCall(fd, call);
  // std::min({a, b, c}) and std::max({...}): folded pairwise, left to right.
  if (fd->isInStdNamespace() && (name == "min" || name == "max") && call->getNumArgs() >= 1)
    if (auto* list = dyn_cast<CXXStdInitializerListExpr>(call->getArg(0)->IgnoreImplicit())) {
      auto* init = dyn_cast<InitListExpr>(list->getSubExpr()->IgnoreImplicit());
      if (!init || init->getNumInits() == 0 || call->getNumArgs() != 1)
        return Fail(call->getBeginLoc(), "std::" + name + " of a list with a comparator in a kernel", "fold it with std::" + name + "(a, b)");
      std::string folded = Expr(init->getInit(0));
      for (unsigned i = 1; i < init->getNumInits(); ++i)
        folded = FoldFunction(name) + "(" + folded + ", " + Expr(init->getInit(i)) + ")";
      return folded;
    }
  std::vector<std::string> args;
  const bool library = IsSystemDecl(fd) || fd->isInStdNamespace() || InNamespace(fd, "LiteMath");
  std::map<unsigned, std::string> bindings;
  if (library)
    for (auto* arg : call->arguments()) args.push_back(Expr(arg));
  else
    args = HelperArgs(fd, call, bindings);
  std::string b = Builtin(fd, args, call);
  if (!b.empty()) return b;
  // A system header outside the compiler's and the C library's folders is the user's, reached with -isystem.
  const std::string file = IsSystemDecl(fd) ? FileOf(m_ctx, fd->getLocation()) : "";
  const bool usersSystemHeader = !file.empty() && file.rfind("/usr/include/", 0) != 0 && file.rfind("/usr/lib/", 0) != 0;
  if (fd->isInStdNamespace() || (IsSystemDecl(fd) && !usersSystemHeader))
    return Fail(call->getBeginLoc(), "unsupported library call '" + qname + "' in a kernel",
                "kernels may call LiteMath, <cmath> and std::min/max/abs, and your own functions with visible bodies");
  if (usersSystemHeader)
    return Fail(call->getBeginLoc(), "'" + qname + "' is declared in a system header: kernels treat those as libraries",
                "pass the folder of the helper's header with -I, not -isystem");
  // The user's own free function.
  std::string callee = EmitHelper(fd, call->getBeginLoc(), false, bindings);
  std::string s = callee + "(";
  for (size_t i = 0; i < args.size(); ++i) s += (i ? ", " : "") + args[i];
  return s + ")";
}

}  // namespace crossrt::engine

namespace crossrt::engine {

}  // namespace crossrt::engine
