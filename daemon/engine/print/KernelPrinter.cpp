// The walk over the statements and expressions one kernel reaches, language by language through
// KernelPrinter's virtual functions. Calls (Calls.cpp), images (Images.cpp), pointers, structs,
// lambdas and the owner of composed objects have files of their own; types and layouts are
// GlslTypes.cpp's.
#include "print/KernelPrinter.h"
#include "analyse/Shadowing.h"
#include "generate/GeneratedNames.h"
#include "print/PrinterParts.h"

#include <clang/AST/ParentMapContext.h>
#include <clang/AST/RecordLayout.h>
#include <clang/Basic/SourceManager.h>
#include <clang/AST/RecursiveASTVisitor.h>
#include <clang/Lex/Lexer.h>

#include <cctype>
#include <cstdio>
#include <map>
#include <set>
#include <functional>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

namespace {

const std::set<std::string>& GlslKeywords() {
  static const std::set<std::string> words = {
      "in", "out", "inout", "input", "output", "uniform", "buffer", "shared", "attribute", "varying",
      "layout", "centroid", "flat", "smooth", "noperspective", "patch", "sample", "coherent",
      "volatile", "restrict", "readonly", "writeonly", "subroutine", "precise", "invariant",
      "discard", "lowp", "mediump", "highp", "precision", "vec2", "vec3", "vec4", "ivec2", "ivec3",
      "ivec4", "uvec2", "uvec3", "uvec4", "bvec2", "bvec3", "bvec4", "mat2", "mat3", "mat4",
      "texture", "filter", "common", "partition", "active", "superp", "output", "resource",
      "mix", "main", "gl_Position", "packed", "half", "fixed", "image1D", "image2D", "image3D", "imageCube", "sampler1D", "sampler2D",
      "sampler3D", "samplerCube", "texture2D", "texture3D",
      // Types named like a buffer block of `image`, `sampler` or `texture` (ShaderCode's <name>Buffer).
      "imageBuffer", "iimageBuffer", "uimageBuffer", "samplerBuffer", "isamplerBuffer", "usamplerBuffer", "textureBuffer",
      "itextureBuffer", "utextureBuffer",
      // Names the generated code gives its own parameters: a user's local of that name is renamed.
      "self",
      // ISPC's keywords and built-ins, for the ISPC dialect of the printer.
      "export", "task", "launch", "sync", "soa", "foreach", "foreach_tiled", "foreach_active", "foreach_unique", "programIndex",
      "programCount", "cif", "cfor", "cdo", "cwhile", "unmasked", "new", "delete", "int8", "int16", "int32", "int64", "uint8",
      "uint16", "uint32", "uint64", "float16", "print",
      // Macros ISPC 1.28 predefines: a constant named so (static constexpr float PI) would be replaced.
      "PI", "FLT_MAX", "FLT_MIN", "DBL_MAX", "DBL_MIN", "F16_MAX", "F16_MIN", "INT8_MAX", "INT8_MIN", "INT16_MAX", "INT16_MIN",
      "INT32_MAX", "INT32_MIN", "INT64_MAX", "INT64_MIN", "UINT8_MAX", "UINT16_MAX", "UINT32_MAX", "UINT64_MAX", "ISPC",
      "TARGET_WIDTH", "TARGET_ELEMENT_WIDTH", "SizeType", "IntMaskType", "UIntMaskType", "UniformMaskType", "alloca", "assert"};
  return words;
}

// GLSL's built-in functions, which a shader may not overload: a helper of the same name is renamed.
bool IsGlslBuiltinFunction(const std::string& name) {
  static const std::set<std::string> names = {
      "radians", "degrees", "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "asinh", "acosh", "atanh",
      "pow", "exp", "log", "exp2", "log2", "sqrt", "inversesqrt", "abs", "sign", "floor", "trunc", "round", "roundEven",
      "ceil", "fract", "mod", "modf", "min", "max", "clamp", "mix", "step", "smoothstep", "isnan", "isinf", "fma", "frexp",
      "ldexp", "length", "distance", "dot", "cross", "normalize", "faceforward", "reflect", "refract", "matrixCompMult",
      "outerProduct", "transpose", "determinant", "inverse", "lessThan", "lessThanEqual", "greaterThan", "greaterThanEqual",
      "equal", "notEqual", "any", "all", "not", "bitCount", "findLSB", "findMSB", "bitfieldExtract", "bitfieldInsert",
      "bitfieldReverse", "uaddCarry", "usubBorrow", "umulExtended", "imulExtended", "packHalf2x16", "unpackHalf2x16",
      "floatBitsToInt", "floatBitsToUint", "intBitsToFloat", "uintBitsToFloat", "barrier", "texture", "textureLod"};
  return names.count(name) > 0;
}

}  // namespace

std::string TrimmedSourceText(const ASTContext& ctx, SourceRange range) {
  auto& sm = ctx.getSourceManager();
  return Lexer::getSourceText(CharSourceRange::getTokenRange(range), sm, ctx.getLangOpts()).str();
}

KernelPrinter::KernelPrinter(ASTContext& ctx, const CXXRecordDecl* cls, Reporter& reporter)
    : m_ctx(ctx), m_class(cls), m_reporter(reporter) {}

// A variable or field named like a GLSL keyword, or like a built-in function (which it would hide
// in GLSL, and shadow in ISPC's standard library: `float distance` in Attenuate), takes a '_'.
std::string KernelPrinter::SafeName(const std::string& name) {
  return GlslKeywords().count(name) || IsGlslBuiltinFunction(name) ? name + "_" : name;
}

// A local that shadows another name takes a suffix (analyse/Shadowing.cpp); the others, SafeName's.
// Asked once per local: every reference to it asks again.
std::string KernelPrinter::LocalName(const VarDecl* vd) {
  if (auto it = renames.find(vd); it != renames.end()) return it->second;
  if (auto it = m_localNames.find(vd); it != m_localNames.end()) return it->second;
  const std::string renamed = ShadowingLocalName(m_ctx, vd);
  if (!renamed.empty()) renames[vd] = renamed;
  return m_localNames[vd] = renamed.empty() ? SafeName(vd->getNameAsString()) : renamed;
}

std::string KernelPrinter::Fail(SourceLocation loc, const std::string& message, const std::string& hint) {
  m_reporter.GpuError(loc, message, hint);
  return "/*error*/";
}

std::string KernelPrinter::DataStruct() const { return dataStruct.empty() ? m_class->getNameAsString() + "_Data" : dataStruct; }

std::optional<std::string> KernelPrinter::Type(QualType t, SourceLocation loc) {
  QualType base = t.getNonReferenceType();
  for (QualType element;;) {  // to the elements of arrays, std::array's too
    if (auto* arr = dyn_cast<ConstantArrayType>(base.getCanonicalType().getTypePtr())) base = arr->getElementType();
    else if (IsStdArray(base, &element)) base = element;
    else break;
  }
  base = base.getCanonicalType();
  if (base->isPointerType()) {
    Fail(loc, "pointer '" + t.getAsString(m_ctx.getPrintingPolicy()) + "' cannot be used here in a kernel",
         "pass arrays to kernels as pointer parameters of the kernel, or use a std::vector member");
    return std::nullopt;
  }
  if (auto* bt = base->getAs<BuiltinType>(); bt && bt->isInteger() && m_ctx.getTypeSize(base) < 32 && bt->getKind() != BuiltinType::Bool) {
    Fail(loc, "type '" + t.getAsString(m_ctx.getPrintingPolicy()) + "' is narrower than 32 bits, and GPU integers are 32-bit",
         "use int or uint32_t in kernels (and mask explicitly where the wrap-around matters)");
    return std::nullopt;
  }
  if (base->isSpecificBuiltinType(BuiltinType::Double))
    if (auto spelled = DoubleType(t)) return spelled;
  if (auto* bt = base->getAs<BuiltinType>(); bt && bt->isFloatingPoint() && bt->getKind() != BuiltinType::Float) {
    Fail(loc, DoubleRefusal(t.getAsString(m_ctx.getPrintingPolicy())), DoubleRefusalHint());
    return std::nullopt;
  }
  auto g = GlslTypeOf(t);
  if (auto* closure = base->getAsCXXRecordDecl(); !g && closure && closure->isLambda()) {
    Fail(loc, "a lambda used other than by calling it in a kernel (passed, copied or returned)",
         "keep it in a local and call it: auto f = [](float x) { ... }; f(v)");
    return std::nullopt;
  }
  if (!g) {
    Fail(loc, "type '" + t.getAsString(m_ctx.getPrintingPolicy()) + "' has no GPU equivalent",
         "kernels may use int, uint, float, bool, LiteMath vectors and matrices, and plain structs of those");
    return std::nullopt;
  }
  if (auto* rd = base->getAsCXXRecordDecl(); rd && !IsLiteMathType(base, nullptr)) NeedStruct(rd);
  return SpellType(t, *g, loc);
}

std::string KernelPrinter::Declare(QualType t, const std::string& name, SourceLocation loc) {
  auto g = Type(t, loc);
  if (!g) return "/*error*/ " + name;
  auto [base, dims] = SplitArray(*g);
  return base + " " + SafeName(name) + dims;
}

void KernelPrinter::NeedStruct(const RecordDecl* rd) {
  rd = rd->getDefinition() ? rd->getDefinition() : rd;
  if (m_emitted.count(rd) || m_inProgress.count(rd) || predeclaredStructs.count(rd->getNameAsString())) return;
  m_inProgress.insert(rd);
  std::ostringstream os;
  if (rd->getQualifiedNameAsString() != rd->getName()) os << "// " << rd->getQualifiedNameAsString() << "\n";
  os << "struct " << rd->getName().str() << " {\n";
  os << StructBody(rd);
  m_inProgress.erase(rd);
  m_emitted.insert(rd);
  m_structs.push_back({rd->getName().str(), os.str()});
}

// Composed code's constants keep its holder's prefix; the namespace-scope constants that objects'
// methods use are shared, as the free functions calling them are (a class's static members are not).
std::string KernelPrinter::ConstantName(const VarDecl* vd) const {
  return (selfClass && !vd->isStaticDataMember() ? "" : composedPrefix) + SafeName(vd->getName().str());
}

std::string KernelPrinter::NeedConstant(const VarDecl* vd) {
  const std::string name = ConstantName(vd);
  if (m_emitted.count(vd)) return name;
  m_emitted.insert(vd);
  const clang::Expr* init = vd->getAnyInitializer();
  std::string value = init ? Expr(init) : "0";
  m_constants.push_back({name, ConstantQualifier() +
                                   Declare(vd->getType(), name, vd->getLocation()) + " = " + value + ";\n"});
  return name;
}

std::string KernelPrinter::PreludeTypes() const {
  std::string out;
  for (auto& s : m_structs) out += s.text + "\n";
  return out;
}

std::string KernelPrinter::Literal(const clang::Expr* e) {
  if (auto* il = dyn_cast<IntegerLiteral>(e)) {
    bool isUnsigned = il->getType()->isUnsignedIntegerType();
    auto v = il->getValue();
    std::string digits = isUnsigned ? std::to_string(v.getZExtValue()) : std::to_string(v.getSExtValue());
    return isUnsigned ? digits + "u" : digits;
  }
  if (auto* fl = dyn_cast<FloatingLiteral>(e)) {
    std::string text;
    if (!e->getBeginLoc().isMacroID()) text = TrimmedSourceText(m_ctx, e->getSourceRange());
    while (!text.empty() && (text.back() == 'f' || text.back() == 'F' || text.back() == 'l' || text.back() == 'L'))
      text.pop_back();
    if (text.empty() || text.find_first_of("xXpP") != std::string::npos) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.9g", fl->getValue().convertToDouble());
      text = buf;
      if (text.find_first_of(".eEin") == std::string::npos) text += ".0";
    }
    if (text.find_first_of(".eE") == std::string::npos) text += ".0";
    return text + FloatSuffix(fl);
  }
  if (auto* bl = dyn_cast<CXXBoolLiteralExpr>(e)) return bl->getValue() ? "true" : "false";
  if (auto* cl = dyn_cast<CharacterLiteral>(e)) return std::to_string(cl->getValue());
  return "/*literal*/";
}

// An explicit or implicit conversion. GLSL converts implicitly only int->uint->float, so spell
// the others out, and fold integer literals into the target type so the code stays readable.
std::string KernelPrinter::Cast(QualType to, const clang::Expr* sub) {
  // On the GPU double precision only arises from promotions such as `x * 0.5` (explicit double
  // variables are refused), and the arithmetic stays in float; a language with doubles may compute
  // in double where the kernel declared one (NarrowedDouble, IntegerToReal).
  if (to->isRealFloatingType() && !to->isSpecificBuiltinType(BuiltinType::Float) && sub->getType()->isFloatingType())
    return Expr(sub);
  if (to->isSpecificBuiltinType(BuiltinType::Float) && sub->getType()->isRealFloatingType() &&
      !sub->getType()->isSpecificBuiltinType(BuiltinType::Float))
    return NarrowedDouble(sub);
  if (to->isRealFloatingType() && !to->isSpecificBuiltinType(BuiltinType::Float) && sub->getType()->isIntegerType()) {
    const clang::Expr* self = nullptr;  // the conversion itself, to see where its value goes
    for (const auto& parent : m_ctx.getParents(*sub))
      if (auto* cast = parent.get<CastExpr>()) self = cast;
    return IntegerToReal(sub, self);
  }
  auto target = GlslTypeOf(to);
  auto source = GlslTypeOf(sub->getType());
  if (!target) return Fail(sub->getBeginLoc(), "conversion to '" + to.getAsString(m_ctx.getPrintingPolicy()) + "' is not supported in kernels", "");
  if (source && *source == *target) return Expr(sub);
  const clang::Expr* bare = sub->IgnoreParenImpCasts();
  if (auto* il = dyn_cast<IntegerLiteral>(bare); il && !il->getType()->isUnsignedIntegerType()) {
    auto v = il->getValue().getSExtValue();
    if (*target == "float") return std::to_string(v) + ".0";
    if (*target == "uint" && v >= 0) return std::to_string(v) + "u";
    if (*target == "int") return std::to_string(v);
  }
  if (*target == "bool") {
    if (source && (*source == "float")) return "((" + Expr(sub) + ") != 0.0)";
    return "((" + Expr(sub) + ") != 0)";
  }
  return ConvertedTo(*target, sub);
}

std::string KernelPrinter::Construct(QualType t, const std::vector<const clang::Expr*>& args, SourceLocation loc) {
  auto g = Type(t, loc);
  if (!g) return "/*error*/";
  std::vector<const clang::Expr*> real;
  for (auto* a : args)
    if (!isa<CXXDefaultArgExpr>(a)) real.push_back(a);
  // Copies and moves are plain values in GLSL.
  if (real.size() == 1 && GlslTypeOf(real[0]->getType()) == GlslTypeOf(t) && IsLiteMathType(real[0]->getType(), "half4") == IsLiteMathType(t, "half4"))
    return Expr(real[0]);
  return ConstructValue(t, *g, real, loc);
}

// push_back to a member vector: the function that appends, written once per vector.
std::string KernelPrinter::EmitAppend(const FieldDecl* field, const CallExpr* call) {
  const std::string vector = field->getNameAsString(), name = vector + "_push_back";
  if (!m_emitted.insert(field).second) return name;
  return AppendFunction(field, call, name);
}

std::string KernelPrinter::EmitHelper(const FunctionDecl* fd, SourceLocation callLoc, bool composedEntry,
                                    const std::map<unsigned, std::string>& bufferBindings, const CXXRecordDecl* structSelf) {
  const FunctionDecl* def = nullptr;
  if (!fd->hasBody(def) || !def) {
    return Fail(callLoc, "function '" + fd->getQualifiedNameAsString() + "' is called from a kernel but its body is not visible",
                "define it in a header or in one of the class's source files");
  }
  // Composed code keeps its names under the holder's prefix: no clash with the kernel's helpers.
  // Methods printed for an object (virtual calls) are per class; free functions are shared.
  std::string name = (selfClass && !isa<CXXMethodDecl>(fd) ? "" : composedPrefix) + FunctionName(fd, structSelf);
  if (IsGlslBuiltinFunction(name)) name += "_";  // GLSL forbids overloading its built-in functions
  // A copy per buffer its pointers index where buffers are globals (GLSL); where buffers are passed
  // (ISPC), one copy serves them all: named after the parameters that point into a buffer.
  for (auto& [index, buffer] : bufferBindings)
    name += PassesBuffers() ? "_at_" + SafeName(def->getParamDecl(index)->getNameAsString()) : "_" + buffer;
  if (m_inProgress.count(def))
    return Fail(callLoc, "recursive call to '" + fd->getQualifiedNameAsString() + "' in a kernel",
                "GPUs have no call stack: rewrite the recursion as a loop with an explicit stack array");
  if (bufferBindings.empty() ? m_emitted.count(def) > 0 : !m_emittedCopies.insert(name).second) return name;
  if (!composedEntry && isa<CXXMethodDecl>(def) && cast<CXXMethodDecl>(def)->isVirtual())
    Fail(callLoc, "virtual call to '" + fd->getQualifiedNameAsString() + "' in a kernel", "call a non-virtual helper");
  m_inProgress.insert(def);
  std::ostringstream os;
  auto ret = Type(def->getReturnType(), def->getLocation());
  os << "// from " << def->getQualifiedNameAsString() << "\n" << FunctionQualifiers(def) << (ret ? *ret : "void") << " " << name << "(";
  // The class's own methods reach its members as the kernels do: through the class data where the
  // language passes it (ClassDataParameter).
  const bool method = isa<CXXMethodDecl>(def) && !cast<CXXMethodDecl>(def)->isStatic();
  const std::string classData = !selfClass && !structSelf && method ? ClassDataParameter() : "";
  const bool withSelf = ((selfClass || structSelf) && method) || !classData.empty();
  if (!classData.empty()) os << classData;
  else if (withSelf && structSelf) {
    if (cast<CXXMethodDecl>(def)->isConst()) os << structSelf->getNameAsString() << " self";
    else os << WritableSelf(structSelf->getNameAsString());
  } else if (withSelf) os << ObjectDataStruct(selfClass) << " self";
  const auto outerPointers = m_pointers;  // this function's pointer parameters shadow the caller's names
  bool first = !withSelf;
  for (unsigned i = 0; i < def->getNumParams(); ++i) {
    auto* p = def->getParamDecl(i);
    QualType pt = p->getType();
    if (IsOwnerParam(p)) {  // the traversal passed to an object's method (Owner.cpp): left out where its data are globals
      const std::string declared = OwnerParameter(p);
      if (declared.empty()) continue;
      os << (first ? "" : ", ") << declared;
      first = false;
      continue;
    }
    std::string qualifier;
    if (pt->isReferenceType() && !pt.getNonReferenceType().isConstQualified()) qualifier = "inout ";
    if (IsImage2D(pt.getNonReferenceType()))
      Fail(p->getLocation(), "helper '" + fd->getNameAsString() + "' takes an Image2D parameter; on the GPU only kernels take images",
           "read the texels in the kernel and pass them to the helper, or make the image a member, which helpers reach directly");
    os << (first ? "" : ", ");
    first = false;
    if (pt->isPointerType()) {
      // A pointer parameter: the element it points at (inout unless const), or the offset into the
      // buffer this copy of the helper is bound to.
      PointerTarget t;
      const std::string name = SafeName(p->getNameAsString());
      if (IsArrayValueParam(p)) {  // const float boxMin[3]: an array by value
        t.array = name;
        t.local = true;
        os << ArrayValueParamQualifier() << Declare(p->getOriginalType().getUnqualifiedType(), p->getNameAsString(), p->getLocation());
      } else if (auto bound = bufferBindings.find(i); bound != bufferBindings.end()) {
        t.array = PassesBuffers() ? name : bound->second;
        t.offset = name + "_offset";
        os << BufferParameter(p, name) << "uint " << t.offset;
      } else {
        t.value = name;
        os << (pt->getPointeeType().isConstQualified() ? Declare(pt->getPointeeType(), p->getNameAsString(), p->getLocation())
                                                       : WritableParam(pt->getPointeeType(), p->getNameAsString(), p->getLocation()));
      }
      m_pointers[p] = t;
      continue;
    }
    os << (qualifier.empty() ? Declare(pt, p->getNameAsString(), p->getLocation()) : WritableParam(pt, p->getNameAsString(), p->getLocation()));
  }
  os << ")\n";
  const CXXRecordDecl* savedSelf = m_structSelf;
  m_structSelf = structSelf;
  os << FunctionBody(def->getBody());
  m_structSelf = savedSelf;
  m_pointers = outerPointers;
  m_inProgress.erase(def);
  if (!m_emitted.count(def)) m_uses.helpers.push_back(def);
  m_emitted.insert(def);
  m_functions.push_back(os.str());
  return name;
}

std::string KernelPrinter::FunctionBody(const clang::Stmt* body) {
  const int savedDepth = m_loopDepth;
  const bool savedThread = m_inThreadBody, savedLoopBody = m_inLoopBody;
  m_loopDepth = 0;
  m_inThreadBody = m_inLoopBody = false;
  std::string out = Stmt(body, 0);
  m_loopDepth = savedDepth;
  m_inThreadBody = savedThread;
  m_inLoopBody = savedLoopBody;
  return out;
}

std::string KernelPrinter::EmitComposedMethod(const CXXMethodDecl* method) {
  return EmitHelper(method, method->getLocation(), true);
}

// `m_holder->Method(args)` where m_holder is a shared_ptr, unique_ptr or pointer to a polymorphic
// class: the composed implementation's function, or "" when the call is not of that form.
std::string KernelPrinter::ComposedCall(const CXXMemberCallExpr* mc) {
  const clang::Expr* obj = mc->getImplicitObjectArgument()->IgnoreParenImpCasts();
  if (auto* op = dyn_cast<CXXOperatorCallExpr>(obj); op && op->getOperator() == OO_Arrow) obj = op->getArg(0)->IgnoreParenImpCasts();
  auto* me = dyn_cast<MemberExpr>(obj);
  auto* field = me ? dyn_cast<FieldDecl>(me->getMemberDecl()) : nullptr;
  if (!field || !isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts())) return "";
  const CXXRecordDecl* pointee = PolymorphicPointee(field->getType());
  if (!pointee) return "";
  const std::string interface = pointee->getNameAsString(), method = mc->getMethodDecl()->getNameAsString();
  const std::string holder = field->getNameAsString();
  if (!compositions.count(interface))
    return Fail(mc->getBeginLoc(), "call of " + interface + "::" + method + " through member '" + holder +
                "' in a kernel, but no implementation of " + interface + " is composed into the class",
                "name the implementation the GPU runs: crossrt_add_class(... COMPOSE " + interface +
                "=<Implementation>), e.g. ISceneObject=BVHScene, and list its source file in SOURCES");
  std::vector<std::string> args;
  if (std::string data = ClassDataArgument(); !data.empty()) args.push_back(data);  // the implementation's data is the class's, under the holder's prefix
  for (auto* arg : mc->arguments()) args.push_back(Expr(arg));
  Type(mc->getType(), mc->getBeginLoc());  // declares a returned struct (CRT_Hit)
  m_uses.composedCalls.insert({holder, method});
  std::string s = holder + "_" + method + "(";
  for (size_t i = 0; i < args.size(); ++i) s += (i ? ", " : "") + args[i];
  return s + ")";
}

// `m_objects[i]->Method(args)` where m_objects is a std::vector of shared_ptr, unique_ptr or plain
// pointers to a polymorphic class: `m_objects_Method(uint(i), args)`, the dispatcher that the
// analysis writes for the implementations it finds; "" when the call is not of that form.
namespace {
// `m_v[i]` where m_v is a member std::vector of pointers to a polymorphic class: m_v, i in `index`.
const FieldDecl* ObjectElement(const clang::Expr* obj, const clang::Expr** index) {
  auto* subscript = dyn_cast<CXXOperatorCallExpr>(obj);
  if (!subscript || subscript->getOperator() != OO_Subscript) return nullptr;
  auto* me = dyn_cast<MemberExpr>(subscript->getArg(0)->IgnoreParenImpCasts());
  auto* field = me ? dyn_cast<FieldDecl>(me->getMemberDecl()) : nullptr;
  QualType element;
  if (!field || !isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts()) || !IsStdVector(field->getType(), &element)) return nullptr;
  if (!PolymorphicPointee(element)) return nullptr;
  if (index) *index = subscript->getArg(1);
  return field;
}
}  // namespace

const FieldDecl* ObjectLocal(const VarDecl* local, const clang::Expr** index) {
  if (!local || !local->isLocalVarDecl() || !local->getType()->isPointerType() || !local->getInit()) return nullptr;
  const clang::Expr* init = local->getInit()->IgnoreParenImpCasts();
  if (auto* get = dyn_cast<CXXMemberCallExpr>(init); get && get->getMethodDecl() && get->getMethodDecl()->getName() == "get" && get->getNumArgs() == 0)
    init = get->getImplicitObjectArgument()->IgnoreParenImpCasts();  // m_v[i].get() of a shared_ptr or unique_ptr
  return ObjectElement(init, index);
}

const FieldDecl* VirtualCallTarget(const CXXMemberCallExpr* mc, const clang::Expr** index) {
  const clang::Expr* obj = mc->getImplicitObjectArgument()->IgnoreParenImpCasts();
  if (auto* op = dyn_cast<CXXOperatorCallExpr>(obj); op && op->getOperator() == OO_Arrow) obj = op->getArg(0)->IgnoreParenImpCasts();
  if (auto* ref = dyn_cast<DeclRefExpr>(obj))  // p->Method() through `T* p = m_v[i]`: p holds i
    if (const FieldDecl* field = ObjectLocal(dyn_cast<VarDecl>(ref->getDecl()))) {
      if (index) *index = ref;
      return field;
    }
  return ObjectElement(obj, index);
}

std::string KernelPrinter::VirtualCall(const CXXMemberCallExpr* mc) {
  const clang::Expr* indexExpr = nullptr;
  const FieldDecl* field = VirtualCallTarget(mc, &indexExpr);
  if (!field) return "";
  auto* method = mc->getMethodDecl();
  if (!method->isVirtual())
    return Fail(mc->getBeginLoc(), "call of the non-virtual " + method->getQualifiedNameAsString() + " through '" + field->getNameAsString() + "' in a kernel",
                "the GPU picks the implementation by the object's type: make the method virtual in the interface");
  auto* local = dyn_cast<DeclRefExpr>(indexExpr);
  std::vector<std::string> args = {local && m_objectLocals.count(local->getDecl()) ? LocalName(cast<VarDecl>(local->getDecl()))  // already the index
                                                                      : ObjectIndex(indexExpr)};
  if (std::string data = ClassDataArgument(); !data.empty()) args.insert(args.begin(), data);  // the dispatcher finds the tags and the objects in the class data
  for (unsigned i = 0; i < mc->getNumArgs(); ++i) {
    const ParmVarDecl* p = i < method->getNumParams() ? method->getParamDecl(i) : nullptr;
    if (p && PointsTo(p->getType(), m_class)) {  // the caller itself, left out on the GPU (print/Owner.cpp)
      if (!PassesSelf(p, mc->getArg(i)))
        return Fail(mc->getArg(i)->getBeginLoc(), "argument " + std::to_string(i + 1) + " of " + method->getNameAsString() + " points at a " +
                    m_class->getNameAsString() + " other than the caller", "pass `this`: on the GPU the caller's data are the only ones");
      continue;
    }
    if (p && p->getType()->isPointerType()) {  // &hit: the value it points at, inout (as a helper's pointer)
      auto t = Pointer(mc->getArg(i));
      if (t && PassesBuffers() && !t->array.empty() && !t->local && !p->getType()->getPointeeType().isConstQualified()) {
        args.push_back(Fail(mc->getArg(i)->getBeginLoc(), "a buffer's element passed to " + method->getNameAsString() + "'s pointer parameter '" +
                            p->getNameAsString() + "' in an ISPC kernel", "pass the address of a local (&hit) and store it into the buffer after the call"));
        continue;
      }
      args.push_back(t ? Pointee(*t, nullptr, mc->getArg(i)->getBeginLoc()) : "/*error*/");
      continue;
    }
    args.push_back(Expr(mc->getArg(i)));
  }
  Type(mc->getType(), mc->getBeginLoc());  // declares a returned struct
  m_uses.virtualCalls.insert({field, method->getCanonicalDecl()});
  m_uses.virtualCallSites.push_back(mc);
  std::string s = generated::VirtualDispatcher(composedPrefix + field->getNameAsString(), method->getNameAsString()) + "(";
  for (size_t i = 0; i < args.size(); ++i) s += (i ? ", " : "") + args[i];
  return s + ")";
}

const CXXRecordDecl* PolymorphicPointee(QualType t) {
  t = t.getCanonicalType();
  const CXXRecordDecl* pointee = nullptr;
  if (t->isPointerType()) pointee = t->getPointeeType()->getAsCXXRecordDecl();
  else if (auto* spec = dyn_cast_or_null<ClassTemplateSpecializationDecl>(t->getAsCXXRecordDecl());
           spec && spec->isInStdNamespace() && (spec->getName() == "shared_ptr" || spec->getName() == "unique_ptr"))
    pointee = spec->getTemplateArgs()[0].getAsType()->getAsCXXRecordDecl();
  if (IsCombinedSamplerPointer(t)) return nullptr;  // a texture (IsTextureArray), not an object of the user's
  return pointee && pointee->hasDefinition() && pointee->isPolymorphic() ? pointee->getDefinition() : nullptr;
}

const ValueDecl* KernelPrinter::ValueParamOf(const clang::Expr* e, bool pointerItself) const {
  e = e->IgnoreParenImpCasts();
  if (pointerItself) {
    auto* dr = dyn_cast<DeclRefExpr>(e);
    return dr && valueParams.count(dr->getDecl()) ? dr->getDecl() : nullptr;
  }
  if (auto* uo = dyn_cast<UnaryOperator>(e); uo && uo->getOpcode() == UO_Deref) return ValueParamOf(uo->getSubExpr(), true);
  if (auto* as = dyn_cast<ArraySubscriptExpr>(e)) {
    clang::Expr::EvalResult r;
    if (as->getIdx()->EvaluateAsInt(r, m_ctx) && r.Val.getInt() == 0) return ValueParamOf(as->getBase(), true);
  }
  return nullptr;
}

// `this->f` in the class this printer prints: an object's field (`self`), a member vector (a buffer),
// a plain member (the class data), under the composed prefix.
std::string KernelPrinter::SelfMember(const MemberExpr* me, const FieldDecl* field) {
  if (auto it = renames.find(me->getMemberDecl()); it != renames.end()) return it->second;
  if (!field) return Fail(me->getBeginLoc(), "member '" + me->getMemberDecl()->getNameAsString() + "' cannot be used here", "");
  if (selfClass) {  // a method of an object the kernel reached through a virtual call: its data is `self`
    if (!GlslTypeOf(field->getType()) || IsStdVector(field->getType()) || field->getType()->isPointerType())
      return Fail(me->getBeginLoc(), "member '" + field->getNameAsString() + "' of " + selfClass->getNameAsString() + " cannot be copied to the GPU",
                  "objects called through virtual functions hold plain data: scalars, LiteMath types and structs of them");
    return "self." + SafeName(field->getNameAsString());
  }
  if (IsTextureArray(field->getType()))
    return Fail(me->getBeginLoc(), "array of textures '" + field->getNameAsString() + "' used as a value in a kernel",
                "call its textures where the array is a member: " + field->getNameAsString() + "[i].sample(uv), " +
                field->getNameAsString() + "[i][p], " + field->getNameAsString() + "[i].width(), " + field->getNameAsString() + ".size()");
  if (IsStdVector(field->getType())) {
    m_uses.memberVectors.insert(field);
    return MemberAccess(field->getNameAsString());
  }
  if (IsImage2D(field->getType()))
    return Fail(me->getBeginLoc(), "Image2D member '" + field->getNameAsString() + "' used as a value in a kernel",
                "use its texels where the image is a member: " + field->getNameAsString() + "[p], at(x, y), sample(sampler, uv), " +
                field->getNameAsString() + "[p] = v, set(x, y, v), width(), height()");
  if (IsImageSampler(field->getType()))
    return Fail(me->getBeginLoc(), "sampler member '" + field->getNameAsString() + "' used as a value in a kernel",
                "pass it straight to an Image2D member's sample(" + field->getNameAsString() + ", uv)");
  const bool spelledDouble = field->getType().getCanonicalType()->isSpecificBuiltinType(BuiltinType::Double) && DoubleType(field->getType());
  if (field->getType()->isPointerType() || (!GlslTypeOf(field->getType()) && !spelledDouble))
    return Fail(me->getBeginLoc(), "member '" + field->getNameAsString() + "' of type '" + field->getType().getAsString(m_ctx.getPrintingPolicy()) +
                "' cannot be used in a kernel", "kernels may use plain data members and std::vector members");
  m_uses.plainMembers.insert(field);
  if (IsSpecializedMember(field)) return SpecializedAccess(field->getNameAsString());
  return MemberAccess(field->getNameAsString());
}

std::string KernelPrinter::Expr(const clang::Expr* e) {
  if (!e) return "";
  if (auto* p = dyn_cast<ParenExpr>(e)) return "(" + Expr(p->getSubExpr()) + ")";
  if (isa<IntegerLiteral, FloatingLiteral, CXXBoolLiteralExpr, CharacterLiteral>(e)) return Literal(e);
  if (auto* ewc = dyn_cast<ExprWithCleanups>(e)) return Expr(ewc->getSubExpr());
  if (auto* mt = dyn_cast<MaterializeTemporaryExpr>(e)) return Expr(mt->getSubExpr());
  if (auto* bt = dyn_cast<CXXBindTemporaryExpr>(e)) return Expr(bt->getSubExpr());
  if (auto* da = dyn_cast<CXXDefaultArgExpr>(e)) return Expr(da->getExpr());
  if (auto* di = dyn_cast<CXXDefaultInitExpr>(e)) return Expr(di->getExpr());
  if (auto* sn = dyn_cast<SubstNonTypeTemplateParmExpr>(e)) return Expr(sn->getReplacement());
  if (auto* ce = dyn_cast<ConstantExpr>(e)) return Expr(ce->getSubExpr());

  if (auto* ic = dyn_cast<ImplicitCastExpr>(e)) {
    switch (ic->getCastKind()) {
      case CK_IntegralCast: case CK_IntegralToFloating: case CK_FloatingToIntegral: case CK_FloatingCast:
      case CK_IntegralToBoolean: case CK_FloatingToBoolean:
        return Cast(ic->getType(), ic->getSubExpr());
      case CK_PointerToBoolean:
        return Fail(e->getBeginLoc(), "pointer tested as a condition in a kernel", "compare an index or a size instead");
      default:
        return Expr(ic->getSubExpr());
    }
  }
  if (auto* ec = dyn_cast<ExplicitCastExpr>(e)) {
    const clang::Expr* sub = ec->getSubExpr()->IgnoreImplicit();
    if (auto* cons = dyn_cast<CXXConstructExpr>(sub)) {
      std::vector<const clang::Expr*> args(cons->arg_begin(), cons->arg_end());
      if (IsUserConstructor(cons->getConstructor())) return ConstructorCall(cons->getConstructor(), args, e->getBeginLoc());
      return Construct(cons->getType(), args, e->getBeginLoc());
    }
    if (ec->getType()->isPointerType())
      return Fail(e->getBeginLoc(), "pointer cast in a kernel", "GLSL has no pointers: index arrays instead");
    if (isa<ParenListExpr, InitListExpr>(sub)) return Expr(sub);
    return Cast(ec->getType(), ec->getSubExpr());
  }
  if (auto* dr = dyn_cast<DeclRefExpr>(e)) {
    const ValueDecl* d = dr->getDecl();
    if (auto it = renames.find(d); it != renames.end()) return it->second;
    if (auto* binding = dyn_cast<BindingDecl>(d); binding && binding->getBinding()) return Expr(binding->getBinding());  // a field of its decomposition
    if (IsImage2D(d->getType().getNonReferenceType()))
      return Fail(e->getBeginLoc(), (imageParams.count(d) ? Described(d) : "Image2D '" + d->getNameAsString() + "'") + " used as a value in a kernel",
                  imageParams.count(d) ? "use its texels in the kernel itself: " + d->getNameAsString() + "[p], at(x, y), sample(sampler, uv), " +
                                             d->getNameAsString() + "[p] = v, set(x, y, v), width(), height()"
                                       : "kernels reach images that are members of the class or Image2D reference parameters of the kernel");
    if (valueParams.count(d))
      return Fail(e->getBeginLoc(), "'" + d->getNameAsString() + "' holds one value per thread (a local of the control function's thread loop), used here as a pointer",
                  "read and write it as *" + d->getNameAsString() + " or " + d->getNameAsString() + "->field");
    if (auto* ec = dyn_cast<EnumConstantDecl>(d)) {
      // Its value, in the type C++ gives it in an expression: an enum with a fixed type (enum class E :
      // uint32_t) keeps it, a plain one promotes (to int, whatever Clang's own underlying type for it).
      const auto* ed = dyn_cast<EnumDecl>(ec->getDeclContext());
      if (ed && (ed->isFixed() ? ed->getIntegerType() : ed->getPromotionType())->isUnsignedIntegerType())
        return std::to_string(ec->getInitVal().getZExtValue()) + "u";
      return std::to_string(ec->getInitVal().getSExtValue());
    }
    if (auto object = m_objectLocals.find(d); object != m_objectLocals.end())
      return Fail(e->getBeginLoc(), "'" + d->getNameAsString() + "' points at an element of " + object->second->getNameAsString() +
                                        ", which kernels hold as its index: it can only call virtual methods here",
                  "call them as " + d->getNameAsString() + "->Method(...); for anything else, keep the element's index and use " +
                      object->second->getNameAsString() + "[index]");
    if (auto* vd = dyn_cast<VarDecl>(d)) {
      if (vd->hasGlobalStorage() && !vd->isStaticLocal()) {
        if (vd->getType().isConstQualified() && vd->getAnyInitializer()) {
          return NeedConstant(vd);
        }
        return Fail(e->getBeginLoc(), "global variable '" + vd->getNameAsString() + "' used in a kernel",
                    "make it constexpr, or a member of the class so it is uploaded to the GPU");
      }
      if (vd->isStaticLocal())
        return Fail(e->getBeginLoc(), "static local variable in a kernel", "use a class member or a constant");
      return LocalName(vd);
    }
    return Fail(e->getBeginLoc(), "'" + d->getNameAsString() + "' cannot be used in a kernel", "");
  }
  if (const ValueDecl* param = ValueParamOf(e)) return SafeName(param->getNameAsString());
  if (auto* me = dyn_cast<MemberExpr>(e); me && me->isArrow() && ValueParamOf(me->getBase(), true))
    return SafeName(ValueParamOf(me->getBase(), true)->getNameAsString()) + "." + SafeName(me->getMemberDecl()->getNameAsString());
  if (auto* me = dyn_cast<MemberExpr>(e)) {
    const clang::Expr* base = me->getBase()->IgnoreParenImpCasts();
    auto* field = dyn_cast<FieldDecl>(me->getMemberDecl());
    if (isa<CXXThisExpr>(base) && m_structSelf) {
      if (!field) return Fail(e->getBeginLoc(), "member function used as a value", "");
      return "self." + SafeName(field->getNameAsString());
    }
    if (isa<CXXThisExpr>(base)) return SelfMember(me, field);
    if (const ParmVarDecl* p = OwnerParamOf(base)) {  // scene->f: as the traversal prints this->f
      const std::string saved = owner->dataPointer;
      owner->dataPointer = SafeName(p->getNameAsString());  // where the class data is passed, the parameter holds it
      const std::string member = owner->SelfMember(me, field);
      owner->dataPointer = saved;
      return member;
    }
    if (!field) return Fail(e->getBeginLoc(), "member function used as a value", "");
    if (IsLiteMathType(me->getBase()->getType(), "half4") || IsLiteMathType(me->getBase()->getType(), "half2"))
      return Fail(e->getBeginLoc(), "a component of a half2 or half4 in a kernel (GPUs keep them packed, two per 32 bits)",
                  "convert it first: to_float4(h).x, float4(h)");
    // LiteMath's matrices keep their columns in m_col, which GLSL's matrices index directly.
    if (field->getName() == "m_col" && (IsLiteMathType(me->getBase()->getType(), "float4x4") || IsLiteMathType(me->getBase()->getType(), "float3x3")))
      return MatrixColumns(Expr(me->getBase()));
    if (me->isArrow()) {  // p->f: the field of what p points at
      auto t = Pointer(me->getBase());
      return t ? Pointee(*t, nullptr, e->getBeginLoc()) + "." + SafeName(field->getNameAsString()) : "/*error*/";
    }
    if (std::string load = FieldRead(me); !load.empty()) return load;
    m_fieldBase = me->getBase()->IgnoreParenImpCasts();
    return Expr(me->getBase()) + "." + SafeName(field->getNameAsString());
  }
  if (auto* as = dyn_cast<ArraySubscriptExpr>(e)) {
    // p[i] through a pointer (a buffer parameter, a pointer local, data()); an array's own elements as written.
    auto* decay = dyn_cast<ImplicitCastExpr>(as->getBase()->IgnoreParens());
    const bool array = decay && decay->getCastKind() == CK_ArrayToPointerDecay;
    if (!array && as->getBase()->getType()->isPointerType()) {
      auto t = Pointer(as->getBase());
      if (!t) return "/*error*/";
      if (std::string load = PointerRead(as, *t); !load.empty()) return load;
      return Pointee(*t, as->getIdx(), e->getBeginLoc());
    }
    return Expr(as->getBase()) + "[" + Expr(as->getIdx()) + "]";
  }
  if (auto* op = dyn_cast<CXXOperatorCallExpr>(e)) {
    if (IsStructOperator(op)) return StructOperatorCall(op);  // a struct's own operator: its code
    if (std::string vector = VectorOperator(op); !vector.empty()) return vector;
    auto kind = op->getOperator();
    if (kind == OO_Subscript)
      if (const ValueDecl* image = ImageTexel(op)) return TexelRead(op, image);
    const clang::Expr* textureIndex = nullptr;
    if (kind == OO_Subscript)
      if (auto* array = TextureElement(op->getArg(0), &textureIndex))
        return TextureTexel(array, textureIndex, op->getArg(1), e->getBeginLoc());
    if (kind == OO_Subscript) {
      // A LiteMath vector's component by a constant index past its end: undefined in C++, an error in GLSL.
      clang::Expr::EvalResult index;
      const auto glsl = GlslTypeOf(op->getArg(0)->getType().getNonReferenceType());
      if (glsl && glsl->find("vec") != std::string::npos && glsl->find("mat") == std::string::npos &&
          op->getArg(1)->EvaluateAsInt(index, m_ctx)) {
        const int64_t n = glsl->back() - '0', i = index.Val.getInt().getExtValue();
        if (i < 0 || i >= n)
          return Fail(op->getArg(1)->getBeginLoc(), "index " + std::to_string(i) + " is out of range of a " + std::to_string(n) +
                      "-component vector (undefined behaviour in C++, rejected by GLSL)", "index components 0 to " + std::to_string(n - 1));
      }
      if (std::string load = ElementRead(op); !load.empty()) return load;
      return Expr(op->getArg(0)) + "[" + Expr(op->getArg(1)) + "]";
    }
    if (std::string store = TexelAssignment(op); !store.empty()) return store;
    if (kind == OO_Equal)
      if (std::string store = WholeStore(op); !store.empty()) return store;
    if (kind == OO_Call && op->getNumArgs() == 3) {  // LiteMath's m(row, col): GLSL's matrices index the column first
      const auto glsl = GlslTypeOf(op->getArg(0)->getType().getNonReferenceType());
      if (glsl && glsl->rfind("mat", 0) == 0) {
        const clang::Expr* m = op->getArg(0)->IgnoreParenImpCasts();
        const std::string matrix = isa<DeclRefExpr>(m) || isa<MemberExpr>(m) ? Expr(m) : "(" + Expr(m) + ")";
        return matrix + "[" + Expr(op->getArg(2)) + "][" + Expr(op->getArg(1)) + "]";
      }
    }
    if (kind == OO_Call)
      if (auto* md = dyn_cast_or_null<CXXMethodDecl>(op->getCalleeDecl()); md && md->getParent()->isLambda()) return LambdaCall(op);
    if (kind == OO_Call) return Fail(e->getBeginLoc(), "call of a function object in a kernel", "call a plain function or a lambda instead");
    if (kind == OO_LessLess || kind == OO_GreaterGreater) {
      if (IsSystemDecl(op->getDirectCallee() ? (const Decl*)op->getDirectCallee() : (const Decl*)m_class))
        return Fail(e->getBeginLoc(), "I/O (stream operator) in a kernel",
                    "kernels cannot do I/O: write results to an output buffer and print them in the control function");
    }
    std::string spelling = getOperatorSpelling(kind);
    if (op->getNumArgs() == 1) return spelling + Expr(op->getArg(0));
    if (op->getNumArgs() == 2 && (kind == OO_PlusPlus || kind == OO_MinusMinus)) return Expr(op->getArg(0)) + spelling;
    if (op->getNumArgs() == 2) return Expr(op->getArg(0)) + " " + spelling + " " + Expr(op->getArg(1));
    return Fail(e->getBeginLoc(), "operator not supported in kernels", "");
  }
  if (auto* bo = dyn_cast<BinaryOperator>(e)) {
    if (bo->isAssignmentOp())
      if (std::string set = Assignment(bo); !set.empty()) return set;
    if (bo->getOpcode() == BO_Div || bo->getOpcode() == BO_Rem)
      if (std::string own = IntegerDivision(bo); !own.empty()) return own;
    const bool division = bo->getOpcode() == BO_Div || bo->getOpcode() == BO_Rem || bo->getOpcode() == BO_DivAssign || bo->getOpcode() == BO_RemAssign;
    const std::string rhs = division ? Divisor(bo) : Expr(bo->getRHS());
    // C++ gives the remainder the dividend's sign; GLSL's % is undefined for negative operands.
    if ((bo->getOpcode() == BO_Rem || bo->getOpcode() == BO_RemAssign) && bo->getType()->isSignedIntegerType()) {
      std::string a = Expr(bo->getLHS()), b = "(" + rhs + ")";
      std::string rem = "(" + a + " - " + b + " * (" + a + " / " + b + "))";
      return bo->getOpcode() == BO_Rem ? rem : a + " = " + rem;
    }
    if (bo->getOpcode() == BO_Comma) return Expr(bo->getLHS()) + ", " + Expr(bo->getRHS());  // GLSL has it too
    return Expr(bo->getLHS()) + " " + bo->getOpcodeStr().str() + " " + rhs;
  }
  if (auto* uo = dyn_cast<UnaryOperator>(e)) {
    auto opc = uo->getOpcode();
    if (opc == UO_Deref && isa<CXXThisExpr>(uo->getSubExpr()->IgnoreParenImpCasts()) && m_structSelf) return "self";  // *this
    if (opc == UO_Deref) {  // *p: what p points at
      auto t = Pointer(uo->getSubExpr());
      return t ? Pointee(*t, nullptr, e->getBeginLoc()) : "/*error*/";
    }
    if (opc == UO_AddrOf)
      return Fail(e->getBeginLoc(), "address-of used as a value in a kernel",
                  "pass &x to a helper's pointer parameter, or set a pointer local from it (T* p = &x)");
    std::string sub = Expr(uo->getSubExpr());
    if (uo->isPostfix()) return sub + UnaryOperator::getOpcodeStr(opc).str();
    return UnaryOperator::getOpcodeStr(opc).str() + sub;
  }
  if (auto* co = dyn_cast<ConditionalOperator>(e))
    return Expr(co->getCond()) + " ? " + Expr(co->getTrueExpr()) + " : " + Expr(co->getFalseExpr());
  if (auto* call = dyn_cast<CallExpr>(e)) return Call(call);
  if (auto* cons = dyn_cast<CXXConstructExpr>(e)) {  // also CXXTemporaryObjectExpr
    std::vector<const clang::Expr*> args(cons->arg_begin(), cons->arg_end());
    if (IsStdArray(cons->getType()) && args.size() == 1 && cons->getConstructor()->isCopyOrMoveConstructor()) return Expr(args[0]);  // arrays copy
    if (IsUserConstructor(cons->getConstructor())) return ConstructorCall(cons->getConstructor(), args, e->getBeginLoc());
    if (args.size() == 1 && args[0]->IgnoreImplicit()->getType()->isConstantArrayType() && IsLiteMathType(cons->getType()))
      return Fail(e->getBeginLoc(), "a LiteMath vector made from an array in a kernel", "name its elements: float3(a[0], a[1], a[2])");
    return Construct(cons->getType(), args, e->getBeginLoc());
  }
  if (auto* il = dyn_cast<InitListExpr>(e)) {
    // std::array<T, N>{...}: its one field, the T[N] it wraps (value-initialised when not listed).
    QualType arrayElement;
    uint64_t arraySize = 0;
    if (IsStdArray(il->getType(), &arrayElement, &arraySize)) {
      if (il->getNumInits() == 1) return Expr(il->getInit(0));
      std::vector<const clang::Expr*> none;
      std::string zero = Construct(arrayElement, none, e->getBeginLoc()), out;
      for (uint64_t i = 0; i < arraySize; ++i) out += (i ? ", " : "") + zero;
      auto g = Type(il->getType(), e->getBeginLoc());
      return ArrayValue(g ? *g : "float", out);
    }
    // The semantic form lists every field (missing ones as ImplicitValueInitExpr), as GLSL needs.
    std::vector<const clang::Expr*> args(il->inits().begin(), il->inits().end());
    if (il->getType()->isArrayType() || !IsLiteMathType(il->getType())) {
      auto g = Type(il->getType(), e->getBeginLoc());
      if (!g) return "/*error*/";
      auto [base, dims] = SplitArray(*g);
      // `float a[4] = {1}`: GLSL needs every element; the rest come from the array filler.
      if (auto* arr = dyn_cast<ConstantArrayType>(il->getType().getCanonicalType().getTypePtr()); arr && il->hasArrayFiller())
        while (args.size() < arr->getSize().getZExtValue()) args.push_back(il->getArrayFiller());
      return ListConstruct(il->getType(), base, dims, args, e->getBeginLoc());
    }
    return Construct(il->getType(), args, e->getBeginLoc());
  }
  if (auto* iv = dyn_cast<ImplicitValueInitExpr>(e)) return Construct(iv->getType(), {}, e->getBeginLoc());
  if (isa<CXXNewExpr, CXXDeleteExpr>(e))
    return Fail(e->getBeginLoc(), std::string(isa<CXXNewExpr>(e) ? "'new'" : "'delete'") + " in a kernel (heap allocation)",
                "GPU threads cannot allocate: use a fixed-size local array or a std::vector member sized before the call");
  if (isa<CXXThrowExpr>(e)) return Fail(e->getBeginLoc(), "'throw' in a kernel", "GPU code has no exceptions: return an error code in an output buffer");
  if (isa<LambdaExpr>(e))
    return Fail(e->getBeginLoc(), "a lambda used other than by calling it in a kernel", "keep it in a local and call it: auto f = [](float x) { ... }; f(v)");
  if (isa<CXXThisExpr>(e) && m_structSelf) return "self";
  if (isa<CXXThisExpr>(e)) return Fail(e->getBeginLoc(), "'this' used as a value in a kernel", "access members directly");
  if (isa<CXXNullPtrLiteralExpr, GNUNullExpr>(e))
    return Fail(e->getBeginLoc(), "nullptr in a kernel", "GPU code has no pointers that may be null: test an index or a count instead "
                                                         "(an element of a vector of objects is never null there: CommitDeviceData refuses one)");
  return Fail(e->getBeginLoc(), std::string("expression '") + e->getStmtClassName() + "' is not supported in kernels",
              "rewrite it with the constructs of the paper's kernels: arithmetic, locals, loops, calls of helpers and members");
}

std::string KernelPrinter::ThreadBody(const clang::Stmt* body, int indent, bool loopBody) {
  m_inThreadBody = true;
  m_inLoopBody = loopBody;
  m_loopDepth = 0;
  std::string out = Stmt(body, indent);
  m_inThreadBody = m_inLoopBody = false;
  return out;
}

std::string KernelPrinter::ThenBranch(const clang::IfStmt* is, int indent) { return Stmt(is->getThen(), isa<CompoundStmt>(is->getThen()) ? indent : indent + 1); }

std::string KernelPrinter::Stmt(const clang::Stmt* s, int indent) {
  std::string pad(indent * 2, ' ');
  if (!s) return pad + ";\n";
  if (auto replaced = replacedStatements.find(s); replaced != replacedStatements.end()) {
    std::string out;
    std::istringstream lines(replaced->second);
    for (std::string line; std::getline(lines, line);) out += (line.empty() ? "" : pad) + line + "\n";
    return out;
  }
  if (auto* cs = dyn_cast<CompoundStmt>(s)) {
    std::string out = pad + "{\n";
    for (auto* c : cs->body()) out += Stmt(c, indent + 1);
    return out + pad + "}\n";
  }
  if (auto* ds = dyn_cast<DeclStmt>(s)) {
    std::string out;
    for (auto* d : ds->decls()) {
      auto* vd = dyn_cast<VarDecl>(d);
      if (!vd) continue;  // local typedefs and such need nothing
      if (auto* closure = vd->getType()->getAsCXXRecordDecl(); closure && closure->isLambda()) continue;  // a lambda: a function of its own where called
      if (auto* dd = dyn_cast<DecompositionDecl>(vd)) {
        // `auto [a, b] = s;`: a variable of its own (named after the bindings), whose fields or
        // elements the bindings are.
        std::string name = "crt";
        for (const BindingDecl* b : dd->bindings()) {
          name += "_" + b->getNameAsString();
          if (auto* holding = b->getHoldingVar())
            Fail(holding->getLocation(), "a structured binding of a tuple-like type in a kernel", "bind the fields of a struct or the elements of an array");
        }
        renames[dd] = name;
        QualType bound = dd->getType().getNonReferenceType();
        const bool isConst = bound.isConstQualified() && !bound->isArrayType();
        out += pad + (isConst ? "const " : "") + Declare(bound, name, dd->getLocation()) + (dd->getInit() ? " = " + Expr(dd->getInit()) : "") + ";\n";
        continue;
      }
      if (vd->isStaticLocal()) { Fail(vd->getLocation(), "static local variable in a kernel", "use a class member or a constant"); continue; }
      QualType t = vd->getType();
      if (t->isPointerType()) {
        out += PointerLocal(vd, pad);
        continue;
      }
      if (t->isReferenceType() && !t.getNonReferenceType().isConstQualified()) {
        std::string why;
        if (auto alias = ReferenceAlias(vd, ds, why)) {  // print/Pointers.cpp: its uses print as what it refers to
          renames[vd] = *alias;
          out += pad + "// " + SafeName(vd->getNameAsString()) + " is " + *alias + " (a reference)\n";
          continue;
        }
        Fail(vd->getLocation(), "non-const reference variable in a kernel: " + why,
             "GLSL has no references: write through the original expression, e.g. arr[i].x = ...");
      }
      std::string decl = Declare(t, LocalName(vd), vd->getLocation());
      std::string cnst = t.getNonReferenceType().isConstQualified() && !t->isArrayType() ? "const " : "";
      out += pad + cnst + LocalQualifier(vd) + decl;
      std::string after;
      if (auto* init = vd->getInit()) {
        const clang::Expr* bare = init->IgnoreImplicit();
        bool trivialDefault = false;
        auto* cons = dyn_cast<CXXConstructExpr>(bare);
        if (cons && cons->getNumArgs() == 0 && cons->getConstructor()->isTrivial())
          trivialDefault = true;
        auto* arr = dyn_cast<ConstantArrayType>(t.getCanonicalType().getTypePtr());
        if (!trivialDefault && cons && cons->getNumArgs() == 0 && arr && arr->getSize().getZExtValue() > 8) {
          // A long array of class type: each element constructed in a loop, not in one long constructor.
          const std::string n = std::to_string(arr->getSize().getZExtValue()), name = LocalName(vd);
          after = pad + "for (int crt_i = 0; crt_i < " + n + "; ++crt_i)  // each element default-constructed, as in C++\n" + pad + "  " +
                  name + "[crt_i] = " + Construct(arr->getElementType(), {}, vd->getLocation()) + ";\n";
        } else if (std::string copy = cons && cons->getNumArgs() == 1 && IsStdArray(t) && cons->getConstructor()->isCopyOrMoveConstructor()
                                          ? ArrayCopy(vd, cons, pad) : "";
                   !copy.empty()) {
          if (!cnst.empty()) out = pad + decl;  // into a variable that is not const
          after = copy;
        } else if (!trivialDefault) {
          out += " = " + Expr(init);
        }
      }
      out += ";\n" + after;
    }
    return out;
  }
  if (auto* is = dyn_cast<IfStmt>(s)) {
    if (is->getConditionVariable() || is->getInit())
      Fail(is->getBeginLoc(), "declaration inside an if condition in a kernel", "declare the variable before the if");
    if (auto taken = GangCondition(is->getCond())) {
      // A branch on the gang's size, which this language fixes: the branch not taken is not printed.
      std::string cond;
      for (char ch : TrimmedSourceText(m_ctx, is->getCond()->getSourceRange()))  // on one line
        if (!std::isspace(static_cast<unsigned char>(ch)) || (!cond.empty() && cond.back() != ' ')) cond += std::isspace(static_cast<unsigned char>(ch)) ? ' ' : ch;
      const clang::Stmt* branch = *taken ? is->getThen() : is->getElse();
      return pad + "// if (" + cond + "): " + (*taken ? "true" : "false") + " with a gang of " + std::to_string(*FixedGangSize()) + "\n" +
             (branch ? Stmt(branch, indent) : "");
    }
    std::string out = pad + "if (" + IfCondition(is->getCond()) + ")\n" + ThenBranch(is, indent);
    if (is->getElse()) out += pad + "else\n" + Stmt(is->getElse(), isa<CompoundStmt>(is->getElse()) ? indent : indent + 1);
    return out;
  }
  auto loopBody = [&](const clang::Stmt* body) {
    ++m_loopDepth;
    std::string b = Stmt(body, isa<CompoundStmt>(body) ? indent : indent + 1);
    --m_loopDepth;
    return b;
  };
  if (auto* fs = dyn_cast<ForStmt>(s)) return ForLoop(fs, indent);
  if (auto* rf = dyn_cast<CXXForRangeStmt>(s)) return RangeFor(rf, indent);
  if (auto* ws = dyn_cast<WhileStmt>(s)) return pad + "while (" + Expr(ws->getCond()) + ")\n" + loopBody(ws->getBody());
  if (auto* dos = dyn_cast<DoStmt>(s)) return pad + "do\n" + loopBody(dos->getBody()) + pad + "while (" + Expr(dos->getCond()) + ");\n";
  if (auto* rs = dyn_cast<ReturnStmt>(s)) {
    if (m_inThreadBody && m_inLoopBody)
      return Fail(s->getBeginLoc(), "'return' inside a parallel kernel loop would end all later iterations",
                  "each iteration is a thread: skip this one with 'continue'"), "";
    if (m_inThreadBody && rs->getRetValue() && !threadReturnsValue)
      return Fail(s->getBeginLoc(), "kernel returns a value", "kernels return void; write results to an output buffer"), "";
    if (m_inConstructor) return pad + "return self;\n";
    return pad + "return" + (rs->getRetValue() ? " " + Expr(rs->getRetValue()) : "") + ";\n";
  }
  if (isa<ContinueStmt>(s)) return pad + (m_inThreadBody && m_loopDepth == 0 ? "return;  // 'continue' ends this thread\n" : "continue;\n");
  if (isa<BreakStmt>(s)) {
    if (m_inThreadBody && m_loopDepth == 0)
      return Fail(s->getBeginLoc(), "'break' out of a parallel kernel loop", "each iteration is a thread: skip it with 'continue'"), "";
    return pad + "break;\n";
  }
  if (auto* sw = dyn_cast<SwitchStmt>(s)) {
    ++m_loopDepth;  // 'break' inside a switch is fine
    std::string out = pad + "switch (" + Expr(sw->getCond()) + ")\n" + Stmt(sw->getBody(), indent);
    --m_loopDepth;
    return out;
  }
  if (auto* cs = dyn_cast<CaseStmt>(s)) return pad + "case " + Expr(cs->getLHS()) + ":\n" + Stmt(cs->getSubStmt(), indent + 1);
  if (auto* ds = dyn_cast<DefaultStmt>(s)) return pad + "default:\n" + Stmt(ds->getSubStmt(), indent + 1);
  if (isa<NullStmt>(s)) return pad + ";\n";
  // `(void)unused;`, `(void)a, (void)b;` or `static_cast<void>(x);` only quiet a C++ warning: nothing to run.
  std::function<bool(const clang::Expr*)> quietsWarning = [&](const clang::Expr* e) {
    e = e->IgnoreParens();
    if (auto* comma = dyn_cast<BinaryOperator>(e); comma && comma->getOpcode() == BO_Comma)
      return quietsWarning(comma->getLHS()) && quietsWarning(comma->getRHS());
    auto* cast = dyn_cast<ExplicitCastExpr>(e);
    return cast && cast->getType()->isVoidType() && !cast->getSubExpr()->HasSideEffects(m_ctx);
  };
  if (auto* e = dyn_cast<clang::Expr>(s); e && quietsWarning(e)) return "";
  // assert(c): the CPU classes check it (they run the user's code); the GPU has nowhere to stop.
  if (auto* e = dyn_cast<clang::Expr>(s); e && e->getBeginLoc().isMacroID() &&
                                            Lexer::getImmediateMacroName(e->getBeginLoc(), m_ctx.getSourceManager(), m_ctx.getLangOpts()) == "assert") {
    const auto range = m_ctx.getSourceManager().getExpansionRange(e->getSourceRange());
    return pad + "// " + Lexer::getSourceText(range, m_ctx.getSourceManager(), m_ctx.getLangOpts()).str() + ": checked by the CPU classes only\n";
  }
  // std::swap(a, b) of two variables or elements: through a temporary, as std::swap does.
  if (auto* call = dyn_cast<CallExpr>(s); call && call->getDirectCallee() && call->getDirectCallee()->isInStdNamespace() &&
                                          call->getDirectCallee()->getName() == "swap" && call->getNumArgs() == 2) {
    const clang::Expr *a = call->getArg(0), *b = call->getArg(1);
    if (a->HasSideEffects(m_ctx, false) || b->HasSideEffects(m_ctx, false))
      return Fail(call->getBeginLoc(), "std::swap of expressions with side effects in a kernel", "swap variables or elements"), "";
    const std::string x = Expr(a), y = Expr(b), tmp = "crt_swap" + std::to_string(m_loopDepth);
    return pad + "{\n" + pad + "  const " + Declare(a->getType().getNonReferenceType().getUnqualifiedType(), tmp, call->getBeginLoc()) + " = " + x + ";\n" +
           pad + "  " + x + " = " + y + ";\n" + pad + "  " + y + " = " + tmp + ";\n" + pad + "}\n";
  }
  if (auto* e = dyn_cast<clang::Expr>(s)) return pad + Expr(e) + ";\n";
  return Fail(s->getBeginLoc(), std::string("statement '") + s->getStmtClassName() + "' is not supported in kernels",
              "kernels may use declarations, if, for, while, do, switch, return, break and continue"), "";
}

}  // namespace crossrt::engine
