// GLSL's library calls: LiteMath and <cmath> as GLSL's built-ins, crossrt::Atomic* with the fences of
// acquire-release order, LiteMath's InterlockedAdd and ReduceAdd.
#include "print/glsl/GlslPrinter.h"
#include "analyse/AstQueries.h"
#include "print/GlslTypes.h"
#include "print/PrinterParts.h"

#include <clang/AST/ParentMapContext.h>
#include <clang/AST/RecordLayout.h>

#include <map>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

// LiteMath's InterlockedAdd(mem, v[, before]) and atomicAdd(mem, v) are GLSL's atomicAdd (relaxed,
// as LiteMath's); its
// ReduceAdd(vector, index, v) adds a finite v to the element (kernel_slicer's ReduceAdd family),
// through a function per member vector.
std::string GlslPrinter::InterlockedCall(const FunctionDecl* fd, const CallExpr* call) {
  const std::string name = fd->getNameAsString();
  if (name == "InterlockedAdd" || name == "atomicAdd") {
    if (call->getNumArgs() < 2) return Fail(call->getBeginLoc(), name + " needs a target and a value", "");
    if (std::string problem = AtomicTargetProblem(call->getArg(0)); !problem.empty())
      return Fail(call->getArg(0)->getExprLoc(), "the target of " + name + " is not in device memory: " + problem,
                  "make the target an element of a std::vector member, a data member, or an element of a kernel's pointer parameter");
    m_uses.floatAtomics |= call->getArg(0)->getType()->isRealFloatingType();
    const std::string add = "atomicAdd(" + Expr(call->getArg(0)) + ", " + Expr(call->getArg(1)) + ")";
    return call->getNumArgs() == 3 ? Expr(call->getArg(2)) + " = " + add : add;
  }
  if (name == "InterlockedAdd3f") {  // (array, offset, float3): three atomic adds to array[offset], [offset + 1], [offset + 2]
    if (call->getNumArgs() != 3) return Fail(call->getBeginLoc(), "InterlockedAdd3f takes an array, an offset and a float3", "");
    auto t = Pointer(call->getArg(0));
    if (!t) return "/*error*/";
    if (!t->value.empty() || t->local)
      return Fail(call->getArg(0)->getExprLoc(), "the array of InterlockedAdd3f is not in device memory",
                  "pass a kernel's pointer parameter or a std::vector member's data()");
    m_uses.floatAtomics = true;
    const std::string at = (t->offset.empty() ? "" : t->offset + " + ") + "(" + Expr(call->getArg(1)) + ")", value = "(" + Expr(call->getArg(2)) + ")";
    return "atomicAdd(" + t->array + "[" + at + "], " + value + ".x), atomicAdd(" + t->array + "[" + at + " + 1], " + value +
           ".y), atomicAdd(" + t->array + "[" + at + " + 2], " + value + ".z)";
  }
  const FieldDecl* field = ThisMemberField(call->getArg(0));
  QualType element;
  if (!field || !IsStdVector(field->getType(), &element))
    return Fail(call->getArg(0)->getBeginLoc(), "ReduceAdd in a kernel adds into a std::vector member", "pass the member vector itself");
  m_uses.memberVectors.insert(field);
  const std::string vector = field->getNameAsString(), helper = vector + "_ReduceAdd";
  const bool isFloat = element->isRealFloatingType();
  m_uses.floatAtomics |= isFloat;
  if (!std::count(m_reduceAddVectors.begin(), m_reduceAddVectors.end(), vector)) {
    m_reduceAddVectors.push_back(vector);
    std::ostringstream os;
    os << "// ReduceAdd(" << vector << ", offset, value) from any number of threads: " << (isFloat ? "a finite value" : "the value")
       << " added to the element\n"
       << "void " << helper << "(uint offset, " << Declare(element, "value", call->getBeginLoc()) << ")\n{\n"
       << (isFloat ? "  if (!(isinf(value) || isnan(value)))\n    " : "  ") << "atomicAdd(" << vector << "[offset], value);\n}\n";
    m_functions.push_back(os.str());
  }
  const clang::Expr* value = call->getArg(call->getNumArgs() - 1);
  return helper + "(uint(" + Expr(call->getArg(1)) + "), " + Expr(value) + ")";
}

// GLSL's built-ins, and LiteMath's functions written out in GLSL.
std::string GlslPrinter::LibraryCall(const FunctionDecl* fd, const std::vector<std::string>& a, const CallExpr* call,
                                     const std::map<std::string, std::string>& same) {
  const std::string n = fd->getNameAsString();
  auto join = [&](const std::string& f) { return CallText(f, a); };
  const std::string arg0Type = call->getNumArgs() ? GlslTypeOf(call->getArg(0)->getType()).value_or("") : "";
  if (n == "to_float4" && call->getNumArgs() == 1 && IsLiteMathType(call->getArg(0)->getType(), "half4"))
    return "vec4(unpackHalf2x16((" + a[0] + ").x), unpackHalf2x16((" + a[0] + ").y))";
  if (n == "to_float2" && call->getNumArgs() == 1 && IsLiteMathType(call->getArg(0)->getType(), "half2")) return "unpackHalf2x16(" + a[0] + ")";
  if (n == "to_float3" && arg0Type == "vec4") return "(" + a[0] + ").xyz";
  if (n == "to_float3") return "vec3(" + a[0] + ")";  // from int3/uint3: a conversion
  if (n == "to_float2" && (arg0Type == "vec4" || arg0Type == "vec3")) return "(" + a[0] + ").xy";
  // C++ rounds halves away from zero; GLSL's round() may round them to even.
  if (n == "round" || n == "roundf") return "(sign(" + a[0] + ") * floor(abs(" + a[0] + ") + 0.5))";
  if (n == "as_int") return "floatBitsToInt(" + a[0] + ")";
  if (n == "as_uint") return "floatBitsToUint(" + a[0] + ")";
  if (n == "as_float") {
    auto t = GlslTypeOf(call->getArg(0)->getType()).value_or("int");
    return (t[0] == 'u' ? "uintBitsToFloat(" : "intBitsToFloat(") + a[0] + ")";
  }
  if (n == "hmin" || n == "hmax") {
    auto t = GlslTypeOf(call->getArg(0)->getType()).value_or("vec3");
    const char* f = n == "hmin" ? "min" : "max";
    std::string v = "(" + a[0] + ")";
    std::string r = std::string(f) + "(" + v + ".x, " + v + ".y)";
    if (t.back() == '3' || t.back() == '4') r = std::string(f) + "(" + r + ", " + v + ".z)";
    if (t.back() == '4') r = std::string(f) + "(" + r + ", " + v + ".w)";
    return r;
  }
  // The lanes' bits as the sum of their weights: one compare of four lanes, each argument read once.
  if (n == "lane_mask_le")
    return "uint(dot(vec4(lessThanEqual(" + a[0] + ", " + a[1] + ")), vec4(1.0, 2.0, 4.0, 8.0)))";
  if (n == "mul4x3") return "(" + a[0] + " * vec4(" + a[1] + ", 1.0)).xyz";
  if (n == "mul3x3") return "(mat3(" + a[0] + ") * " + a[1] + ")";
  if (n == "fmod" || n == "fmodf") return "(" + a[0] + " - " + a[1] + " * trunc(" + a[0] + " / " + a[1] + "))";
  // The magnitude of the first and the sign bit of the second, as C++ has it (signed zeros, NaNs too).
  if (n == "copysign" || n == "copysignf")
    return "uintBitsToFloat((floatBitsToUint(" + a[0] + ") & 0x7FFFFFFFu) | (floatBitsToUint(" + a[1] + ") & 0x80000000u))";
  // LiteMath's float4 as a 3-vector and a w: the cross product of the xyz parts, w = 0.
  if ((n == "cross3" || n == "cross") && arg0Type == "vec4") return "vec4(cross((" + a[0] + ").xyz, (" + a[1] + ").xyz), 0.0)";
  if (n == "mul4x4x4" || (n == "mul" && call->getNumArgs() == 2 && arg0Type.rfind("mat", 0) == 0)) {
    const std::string arg1Type = GlslTypeOf(call->getArg(1)->getType()).value_or("");
    if (arg0Type == "mat4" && arg1Type == "vec3") return "(" + a[0] + " * vec4(" + a[1] + ", 1.0)).xyz";
    return "(" + a[0] + " * " + a[1] + ")";
  }
  if (n == "make_float4x4_from_rows" || n == "make_float3x3_from_rows" || n == "make_float3x3")
    return std::string("transpose(") + (n == "make_float4x4_from_rows" ? "mat4(" : "mat3(") + a[0] + ", " + a[1] + ", " + a[2] + (a.size() > 3 ? ", " + a[3] : "") + "))";
  if (n == "make_float4x4_from_cols" || n == "make_float3x3_from_cols" || n == "make_float3x3_by_columns")
    return std::string(n == "make_float4x4_from_cols" ? "mat4(" : "mat3(") + a[0] + ", " + a[1] + ", " + a[2] + (a.size() > 3 ? ", " + a[3] : "") + ")";
  if (n == "rcp") return "(1.0 / " + a[0] + ")";
  if (n == "isfinite") return "!(isinf(" + a[0] + ") || isnan(" + a[0] + "))";
  auto it = same.find(n);
  if (it != same.end()) return join(it->second);
  return "";
}

// The gang (Gang.h): a GPU thread here is a gang of one, so each function is what one thread alone
// does, and a CRT_UNIFORM local is a thread's own.
std::string GlslPrinter::GangCall(const FunctionDecl* fd, const CallExpr* call) {
  if (fd->getName() == "GangSize") return "1";
  if (fd->getName() == "AllLanesOn") return "true";
  if (fd->getName() == "LaneIndex") return "0";
  if (fd->getName() == "LaneOf") return "(" + Expr(call->getArg(0)) + ")[min(" + Expr(call->getArg(1)) + ", 3)]";
  if (fd->getName() == "LaneOfQuad") return "(" + Expr(call->getArg(0)) + ")[0]";
  if (fd->getName() == "LaneBits") return "((" + Expr(call->getArg(0)) + ") ? 1u : 0u)";
  return "(" + Expr(call->getArg(0)) + ")";  // AnyLane, AllLanes, FirstLane, MinOverLanes, LaneValue, FromLane: the thread's own value
}

std::string GlslPrinter::LocalQualifier(const VarDecl*) { return ""; }

std::string GlslPrinter::AtomicOperation(const std::string& name, const std::vector<std::string>& args) {
  // The fences of acquire-release order (the kernel template defines crt_release/crt_acquire):
  // the last argument passes a release fence before the atomic runs, the result an acquire fence
  // after. crossrt::AtomicCompareExchange is atomicCompSwap; the others keep their name.
  std::string s = "crt_acquire(" + (name == "AtomicCompareExchange" ? std::string("atomicCompSwap") : "atomic" + name.substr(6)) + "(";
  for (size_t i = 0; i < args.size(); ++i) {
    s += i ? ", " : "";
    s += i + 1 == args.size() ? "crt_release(" + args[i] + ")" : args[i];
  }
  return s + "))";
}

std::string GlslPrinter::BitArgument(const std::string& value, const clang::Expr*) const { return "uint(" + value + ")"; }

std::string GlslPrinter::FoldFunction(const std::string& name) const { return name; }

}  // namespace crossrt::engine
