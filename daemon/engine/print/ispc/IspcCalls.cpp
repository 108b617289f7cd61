// ISPC's library calls: LiteMath.isph's names for LiteMath and <cmath>, ISPC's global atomics for
// crossrt::Atomic*, LiteMath's InterlockedAdd and ReduceAdd.
#include "print/ispc/IspcPrinter.h"
#include "print/ispc/IspcTypes.h"
#include "analyse/AstQueries.h"
#include "print/GlslTypes.h"
#include "print/PrinterParts.h"

#include <clang/AST/ParentMapContext.h>
#include <clang/AST/RecordLayout.h>

#include <map>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

// LiteMath.isph has LiteMath's constructors and conversions under their own
// names (make_float3, to_float3), GLSL's functions under GLSL's (`same`), and LiteMath's matrices.
std::string IspcPrinter::LibraryCall(const FunctionDecl* fd, const std::vector<std::string>& a, const CallExpr* call,
                                     const std::map<std::string, std::string>& same) {
  const std::string n = fd->getNameAsString();
  auto join = [&](const std::string& f) { return CallText(f, a); };
  static const std::set<std::string> ownNames = {
      "make_float2", "make_float3", "make_float4", "make_int2", "make_int3", "make_int4", "make_uint2", "make_uint3",
      "make_uint4", "to_float2", "to_float3", "to_float4", "to_int2", "to_int3", "to_int4", "to_uint2", "to_uint3", "to_uint4"};
  const std::string arg0Type = call->getNumArgs() ? GlslTypeOf(call->getArg(0)->getType()).value_or("") : "";
  if (n == "to_float4" && call->getNumArgs() == 1 && IsLiteMathType(call->getArg(0)->getType(), "half4")) return "crt_half4_to_float4(" + a[0] + ")";
  if (n == "to_float2" && call->getNumArgs() == 1 && IsLiteMathType(call->getArg(0)->getType(), "half2")) return "crt_half2_to_float2(" + a[0] + ")";
  if (n.find("half") != std::string::npos) return Unsupported(call->getBeginLoc(), "LiteMath's '" + n + "'");
  // to_int3(v), to_float3(int3): a conversion (as many components); to_float3(float4): a part.
  if (n.rfind("to_", 0) == 0 && call->getNumArgs() == 1 && !arg0Type.empty() && arg0Type.back() == n.back())
    return "make_" + n.substr(3) + "(" + a[0] + ")";
  if (ownNames.count(n)) return join(n);
  if (n == "round" || n == "roundf") return "(sign(" + a[0] + ") * floor(abs(" + a[0] + ") + 0.5f))";
  if (n == "as_int") return "floatBitsToInt(" + a[0] + ")";
  if (n == "as_uint") return "floatBitsToUint(" + a[0] + ")";
  if (n == "as_float") return (arg0Type[0] == 'u' ? "uintBitsToFloat(" : "intBitsToFloat(") + a[0] + ")";
  if (n == "hmin" || n == "hmax") {  // in LiteMath's order of std::min/max
    const std::string f = n == "hmin" ? "crt_min(" : "crt_max(";
    const std::string v = "(" + a[0] + ")";
    const char last = arg0Type.back();
    const std::string r = last == '2'   ? f + v + ".x, " + v + ".y)"
                          : last == '3' ? f + v + ".x, " + f + v + ".y, " + v + ".z))"
                                        : f + f + v + ".x, " + v + ".y), " + f + v + ".z, " + v + ".w))";
    return call->getArg(0)->HasSideEffects(m_ctx) ? Unsupported(call->getBeginLoc(), "hmin/hmax of an expression with side effects") : r;
  }
  // As C++ compares (LiteMath.isph): a NaN or a signed zero comes out as in the C++ class.
  if (n == "min" || n == "max" || n == "clamp") return join("crt_" + n);
  if (n == "fmod" || n == "fmodf") return "(" + a[0] + " - " + a[1] + " * trunc(" + a[0] + " / " + a[1] + "))";
  if (n == "rcp") return "(1.0f / " + a[0] + ")";
  if (n == "isfinite") return "!(isinf(" + a[0] + ") || isnan(" + a[0] + "))";
  if (n == "copysign" || n == "copysignf")
    return "uintBitsToFloat((floatBitsToUint(" + a[0] + ") & 0x7FFFFFFFu) | (floatBitsToUint(" + a[1] + ") & 0x80000000u))";
  if ((n == "cross3" || n == "cross") && arg0Type == "vec4")
    return "make_float4(cross(to_float3(" + a[0] + "), to_float3(" + a[1] + ")), 0.0f)";
  // LiteMath.isph has the matrices' arithmetic and constructors by LiteMath's names.
  static const std::set<std::string> matrixNames = {
      "make_float3x3", "make_float3x3_from_rows", "make_float3x3_from_cols", "make_float3x3_by_columns", "make_float4x4_from_rows",
      "make_float4x4_from_cols", "transpose", "inverse", "inverse4x4", "determinant", "outerProduct", "mul", "mul4x3", "mul3x3",
      "mul4x4x4", "lane_mask_le"};
  if (matrixNames.count(n)) return join(n);
  if (arg0Type.rfind("mat", 0) == 0 || n.find("float4x4") != std::string::npos || n.find("float3x3") != std::string::npos)
    return Unsupported(call->getBeginLoc(), "'" + fd->getQualifiedNameAsString() + "'");
  if (n == "atan2" || n == "atan2f") return join("atan2");
  if (n == "sqrt" || n == "sqrtf") return join("sqrt");
  auto it = same.find(n);
  if (it != same.end()) return join(it->second);
  return "";
}

// LiteMath's ReduceAdd(vector, index, v) and InterlockedAdd3f(array, offset, v) in ISPC: its global
// atomic adds, each lane's to its own element (a finite v only, for ReduceAdd, as LiteMath's;
// InterlockedAdd3f is LiteMath.isph's).
std::string IspcPrinter::Interlocked(const FunctionDecl* fd, const CallExpr* call) {
  const std::string name = fd->getNameAsString();
  if (name == "InterlockedAdd3f") {
    if (call->getNumArgs() != 3) return Fail(call->getBeginLoc(), "InterlockedAdd3f takes an array, an offset and a float3", "");
    // The array: a kernel's pointer parameter, or a member vector's data().
    const clang::Expr* array = call->getArg(0)->IgnoreParenImpCasts();
    std::string base;
    if (auto* dr = dyn_cast<DeclRefExpr>(array); dr && isa<ParmVarDecl>(dr->getDecl()) && dr->getType()->isPointerType() && !m_pointers.count(dr->getDecl()))
      base = Expr(array);
    else if (auto* mc = dyn_cast<CXXMemberCallExpr>(array); mc && mc->getMethodDecl() && mc->getMethodDecl()->getName() == "data")
      if (auto* f = ThisMemberField(mc->getImplicitObjectArgument()); f && IsStdVector(f->getType())) {
        m_uses.memberVectors.insert(f);
        base = Member(f->getNameAsString());
      }
    if (base.empty())
      return Fail(call->getArg(0)->getExprLoc(), "the array of InterlockedAdd3f is not in device memory",
                  "pass a kernel's pointer parameter or a std::vector member's data()");
    return "InterlockedAdd3f(" + base + ", (int)(" + Expr(call->getArg(1)) + "), " + Expr(call->getArg(2)) + ")";  // LiteMath.isph
  }
  if (name != "ReduceAdd") return Unsupported(call->getBeginLoc(), "LiteMath's '" + fd->getQualifiedNameAsString() + "'");
  const FieldDecl* field = ThisMemberField(call->getArg(0));
  QualType element;
  if (!field || !IsStdVector(field->getType(), &element))
    return Fail(call->getArg(0)->getBeginLoc(), "ReduceAdd in a kernel adds into a std::vector member", "pass the member vector itself");
  if (!element->isRealFloatingType() && !element->isIntegerType())
    return Unsupported(call->getBeginLoc(), "ReduceAdd into a vector of '" + element.getAsString(m_ctx.getPrintingPolicy()) + "'");
  m_uses.memberVectors.insert(field);
  const std::string vector = field->getNameAsString(), helper = vector + "_ReduceAdd";
  const bool isFloat = element->isRealFloatingType();
  if (!std::count(m_reduceAddVectors.begin(), m_reduceAddVectors.end(), vector)) {
    m_reduceAddVectors.push_back(vector);
    std::ostringstream os;
    os << "// ReduceAdd(" << vector << ", offset, value) from the lanes: " << (isFloat ? "a finite value" : "the value")
       << " added to each lane's element\n"
       << "static void " << helper << "(uniform " << DataStruct() << " *uniform self, uint offset, " << Declare(element, "value", call->getBeginLoc()) << ")\n{\n"
       << (isFloat ? "  if (!(isinf(value) || isnan(value)))\n    " : "  ") << "atomic_add_global(&" << Member(vector) << "[offset], value);\n}\n";
    m_functions.push_back(os.str());
  }
  const clang::Expr* value = call->getArg(call->getNumArgs() - 1);
  return helper + "(self, ((" + Variability(call->getArg(1)) + "uint)(" + Expr(call->getArg(1)) + ")), " + Expr(value) + ")";
}

// ISPC's global atomics, on the target's address (a lane at a time where lanes share one).
std::string IspcPrinter::AtomicOperation(const std::string& name, const std::vector<std::string>& args) {
  static const std::map<std::string, std::string> names = {
      {"AtomicAdd", "atomic_add_global"}, {"AtomicAnd", "atomic_and_global"},       {"AtomicOr", "atomic_or_global"},
      {"AtomicXor", "atomic_xor_global"}, {"AtomicExchange", "atomic_swap_global"}, {"AtomicMin", "atomic_min_global"},
      {"AtomicMax", "atomic_max_global"}, {"AtomicCompareExchange", "atomic_compare_exchange_global"}};
  std::string s = names.at(name) + "(&" + args[0];
  for (size_t i = 1; i < args.size(); ++i) s += ", crt_perLane(" + args[i] + ")";  // once per lane, as threads do
  return s + ")";
}

// LiteMath's InterlockedAdd(mem, v[, before]) and atomicAdd: ISPC's global atomic add (int, uint and
// float), on the target's address; ReduceAdd and InterlockedAdd3f through Interlocked.
std::string IspcPrinter::InterlockedCall(const FunctionDecl* fd, const CallExpr* call) {
  const std::string name = fd->getNameAsString();
  if ((name != "InterlockedAdd" && name != "atomicAdd") || call->getNumArgs() < 2) return Interlocked(fd, call);
  if (std::string problem = AtomicTargetProblem(call->getArg(0)); !problem.empty())
    return Fail(call->getArg(0)->getExprLoc(), "the target of " + name + " is not in device memory: " + problem,
                "make the target an element of a std::vector member, a data member, or an element of a kernel's pointer parameter");
  // crt_perLane: a uniform value on a uniform target would be added once per gang, not per lane.
  const std::string add = "atomic_add_global(&" + Expr(call->getArg(0)) + ", crt_perLane(" + Expr(call->getArg(1)) + "))";
  return call->getNumArgs() == 3 ? Expr(call->getArg(2)) + " = " + add : add;
}

std::string IspcPrinter::BitArgument(const std::string& value, const clang::Expr* arg) const {
  return (Uniform(arg) ? "((uniform uint)(" : "((uint)(") + value + "))";  // a shared value's bits stay shared
}

std::string IspcPrinter::FoldFunction(const std::string& name) const { return "crt_" + name; }

}  // namespace crossrt::engine
