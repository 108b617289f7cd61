// GLSL's spellings of what KernelPrinter walks: types and structs, conversions and constructors,
// functions' parameters, members of the class data, vectors and operators (GlslPrinter.h).
#include "print/glsl/GlslPrinter.h"
#include "analyse/AstQueries.h"
#include "generate/GeneratedNames.h"
#include "print/GlslTypes.h"
#include "print/PrinterParts.h"

#include <clang/AST/ParentMapContext.h>
#include <clang/AST/RecordLayout.h>

#include <map>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

// LiteMath's half2 and half4 hold their 16-bit floats two per uint (packHalf2x16); float4(h) and
// to_float4(h) unpack them. Their components are reached only through that conversion.
std::string GlslPrinter::HalfConstruct(QualType t, const std::vector<const clang::Expr*>& args, SourceLocation loc) {
  const bool four = IsLiteMathType(t, "half4");
  if (IsLiteMathType(t, "float4")) {  // float4(half4)
    const std::string h = Expr(args[0]);
    return "vec4(unpackHalf2x16((" + h + ").x), unpackHalf2x16((" + h + ").y))";
  }
  std::vector<std::string> a;
  for (auto* arg : args) a.push_back(Expr(arg));
  auto pair = [](const std::string& x, const std::string& y) { return "packHalf2x16(vec2(" + x + ", " + y + "))"; };
  if (args.empty()) return four ? "uvec2(0u)" : "0u";
  if (args.size() == 1 && IsLiteMathType(args[0]->getType(), "float4")) return "uvec2(packHalf2x16((" + a[0] + ").xy), packHalf2x16((" + a[0] + ").zw))";
  if (args.size() == 1 && IsLiteMathType(args[0]->getType(), "float2")) return "packHalf2x16(" + a[0] + ")";
  if (args.size() == 1 && args[0]->getType()->isArithmeticType()) return four ? "uvec2(" + pair(a[0], a[0]) + ")" : pair(a[0], a[0]);
  if (four && args.size() == 4) return "uvec2(" + pair(a[0], a[1]) + ", " + pair(a[2], a[3]) + ")";
  if (!four && args.size() == 2) return pair(a[0], a[1]);
  return Fail(loc, "this construction of LiteMath::" + t.getUnqualifiedType().getAsString(m_ctx.getPrintingPolicy()) + " is not supported in kernels",
              "build it from a float4 (half4(v)) or from four floats");
}

std::string GlslPrinter::WritableParam(QualType type, const std::string& name, SourceLocation loc) { return "inout " + Declare(type, name, loc); }

// Vulkan's shaders have no double (the analysis refuses the type with a hint).
std::optional<std::string> GlslPrinter::DoubleType(QualType) { return std::nullopt; }

std::optional<std::string> GlslPrinter::SpellType(QualType, const std::string& gpuType, SourceLocation) { return gpuType; }

std::string GlslPrinter::StructBody(const RecordDecl* rd) {
  std::ostringstream os;
  for (auto* f : rd->fields()) os << "  " << Declare(f->getType(), f->getName().str(), f->getLocation()) << ";\n";
  os << "};\n";
  return os.str();
}

std::string GlslPrinter::ConstantQualifier() const { return "const "; }

std::string GlslPrinter::FloatSuffix(const FloatingLiteral*) const { return ""; }
// GLSL has no literal for either; glslang folds these.
std::string GlslPrinter::FloatInfinity() const { return "(1.0 / 0.0)"; }
std::string GlslPrinter::FloatNaN() const { return "(0.0 / 0.0)"; }

std::string GlslPrinter::NarrowedDouble(const clang::Expr* sub) { return Expr(sub); }

std::string GlslPrinter::IntegerToReal(const clang::Expr* sub, const clang::Expr*) { return "float(" + Expr(sub) + ")"; }

std::string GlslPrinter::ConvertedTo(const std::string& target, const clang::Expr* sub) { return target + "(" + Expr(sub) + ")"; }

// GLSL's constructors: LiteMath's types by their GLSL names (matrices transposed: LiteMath lists
// rows, GLSL columns), arrays and value-initialised structs element by element.
std::string GlslPrinter::ConstructValue(QualType t, const std::string& type, const std::vector<const clang::Expr*>& real, SourceLocation loc) {
  const std::optional<std::string> g = type;
  if (IsLiteMathType(t, "half4") || IsLiteMathType(t, "half2") || (real.size() == 1 && IsLiteMathType(real[0]->getType(), "half4")))
    return HalfConstruct(t, real, loc);
  auto [base, dims] = SplitArray(*g);
  bool matrix = IsLiteMathType(t, "float4x4") || IsLiteMathType(t, "float3x3");
  std::string out = base + dims + "(";
  if (real.empty()) {
    if (matrix) return base + "(1.0)";  // LiteMath matrices start as the identity
    if (auto* arr = dyn_cast<ConstantArrayType>(t.getCanonicalType().getTypePtr())) {
      // Every element default-constructed, as C++ does for an array of class type.
      const std::string element = Construct(arr->getElementType(), {}, loc);
      std::string list;
      for (uint64_t i = 0; i < arr->getSize().getZExtValue(); ++i) list += (i ? ", " : "") + element;
      return base + dims + "(" + list + ")";
    }
    if (IsLiteMathType(t)) return base + "(0)";
    auto* rd = t.getCanonicalType()->getAsCXXRecordDecl();
    if (!rd) return base + "(0)";  // a value-initialised scalar
    // Value-initialised struct: default member initialisers, else zero.
    bool first = true;
    for (auto* f : rd->fields()) {
      auto fg = Type(f->getType(), loc);
      std::string value = f->hasInClassInitializer() && f->getInClassInitializer() ? Expr(f->getInClassInitializer())
                          : fg ? SplitArray(*fg).first + SplitArray(*fg).second + "(0)" : "0";
      out += (first ? "" : ", ") + value;
      first = false;
    }
    return out + ")";
  }
  for (size_t i = 0; i < real.size(); ++i) out += (i ? ", " : "") + Expr(real[i]);
  out += ")";
  // LiteMath lists matrix elements row by row; GLSL constructors take them column by column.
  if (matrix && real.size() > 1) return "transpose(" + out + ")";
  return out;
}

// Every thread takes a slot from an atomic counter, the vector's size in the class-data block. A
// push past the capacity is counted but not stored; the generated class reports it when it reads
// the size back.
std::string GlslPrinter::AppendFunction(const FieldDecl* field, const CallExpr* call, const std::string& name) {
  const std::string vector = field->getNameAsString();
  QualType element;
  IsStdVector(field->getType(), &element);
  std::ostringstream os;
  os << "// " << vector << ".push_back(value), from any number of threads at once\n"
     << "void " << name << "(" << Declare(element, "value", call->getBeginLoc()) << ")\n"
     << "{\n"
     << "  const uint slot = atomicAdd(" << generated::SizeField(vector) << ", 1u);\n"
     << "  if (slot < " << generated::CapacityField(vector) << ")\n"
     << "    " << vector << "[slot] = value;\n"
     << "}\n";
  m_functions.push_back(os.str());
  return name;
}

// GLSL has no qualifier for it: a helper the user marked noinline is inlined as the compiler likes.
std::string GlslPrinter::FunctionQualifiers(const clang::FunctionDecl*) const { return ""; }

std::string GlslPrinter::ClassDataParameter() const { return ""; }  // the class data is a global block

std::string GlslPrinter::ClassDataArgument() const { return ""; }

std::string GlslPrinter::WritableSelf(const std::string& structName) const { return "inout " + structName + " self"; }

std::string GlslPrinter::ObjectDataStruct(const CXXRecordDecl* cls) const { return cls->getNameAsString() + "_Data"; }

std::string GlslPrinter::OwnerParameter(const ParmVarDecl*) { return ""; }  // the traversal's data are globals

bool GlslPrinter::PassesBuffers() const { return false; }

std::string GlslPrinter::ArrayValueParamQualifier() const { return ""; }  // GLSL passes arrays by value

std::string GlslPrinter::BufferParameter(const ParmVarDecl*, const std::string&) { return ""; }

std::string GlslPrinter::ObjectIndex(const clang::Expr* index) { return "uint(" + Expr(index) + ")"; }

std::string GlslPrinter::ObjectLocalIndex(const std::string& index) const { return "uint(" + index + ")"; }

std::string GlslPrinter::MemberAccess(const std::string& name) const { return ComposedName(name); }

std::string GlslPrinter::SpecializedAccess(const std::string& name) const { return generated::SpecializedConstant(ComposedName(name)); }

std::string GlslPrinter::SizeAsInt(const std::string& size) const { return "int(" + size + ")"; }

std::string GlslPrinter::EmptyTest(const std::string& size) const { return "(" + size + " == 0u)"; }

std::string GlslPrinter::SizeLiteral(uint64_t n) const { return std::to_string(n) + "u"; }

// An assignment to a texel of a float or uint image (imageStore), or to part of one (refused).
std::string GlslPrinter::Assignment(const BinaryOperator* bo) {
  const clang::Expr* e = bo;
  // m_img[p].x = v: the analysis reports it for members; parameters here.
  const clang::Expr* part = bo->getLHS()->IgnoreParenImpCasts();
  while (auto* me = dyn_cast<MemberExpr>(part)) part = me->getBase()->IgnoreParenImpCasts();
  if (part != bo->getLHS()->IgnoreParenImpCasts())
    if (auto* image = ImageTexel(part); image && !isa<FieldDecl>(image))
      return Fail(e->getBeginLoc(), "kernel writes part of a texel of " + Described(image),
                  "GPU images store whole texels: read the texel into a variable, change it, and write it back with " +
                      image->getNameAsString() + "[p] = value");
  if (ImageTexel(bo->getLHS())) {  // a texel of a float or uint image
    if (bo->getOpcode() == BO_Assign) return ImageStore(bo->getLHS(), Expr(bo->getRHS()), e);
    if (bo->getLHS()->HasSideEffects(m_ctx, /*IncludePossibleEffects=*/false))  // it is printed twice
      return Fail(e->getBeginLoc(), "compound assignment to a texel whose coordinate has side effects", "compute the coordinate into a variable first");
    std::string spelling = BinaryOperator::getOpcodeStr(BinaryOperator::getOpForCompoundAssignment(bo->getOpcode())).str();
    return ImageStore(bo->getLHS(), Expr(bo->getLHS()) + " " + spelling + " (" + Expr(bo->getRHS()) + ")", e);
  }
  return "";
}

std::string GlslPrinter::Divisor(const BinaryOperator* bo) { return Expr(bo->getRHS()); }

std::string GlslPrinter::MatrixColumns(const std::string& matrix) const { return matrix; }  // GLSL's matrices index their columns

std::string GlslPrinter::MatrixObject(const std::string& matrix) const { return matrix; }

std::string GlslPrinter::VectorOperator(const CXXOperatorCallExpr*) { return ""; }  // GLSL has LiteMath's operators

std::string GlslPrinter::ElementRead(const CXXOperatorCallExpr*) { return ""; }

std::string GlslPrinter::WholeStore(const CXXOperatorCallExpr*) { return ""; }

std::string GlslPrinter::PointerRead(const ArraySubscriptExpr*, const PointerTarget&) { return ""; }

std::string GlslPrinter::FieldRead(const MemberExpr*) { return ""; }

std::string GlslPrinter::ArrayValue(const std::string& type, const std::string& list) { return type + "(" + list + ")"; }

std::string GlslPrinter::ListConstruct(QualType, const std::string& base, const std::string& dims, const std::vector<const clang::Expr*>& args,
                                       SourceLocation) {
  std::string out = base + dims + "(";
  for (size_t i = 0; i < args.size(); ++i) out += (i ? ", " : "") + Expr(args[i]);
  return out + ")";
}

std::string GlslPrinter::RangeCounter(bool) const { return "int "; }

std::string GlslPrinter::LoopInit(const ForStmt*, const std::string& init) { return init; }

std::string GlslPrinter::ArrayCopy(const VarDecl*, const CXXConstructExpr*, const std::string&) { return ""; }  // GLSL's arrays copy whole

std::string GlslPrinter::VectorMethod(const FieldDecl*, const CXXMemberCallExpr*, const std::string&) { return ""; }

std::string GlslPrinter::MatrixRow(const CXXMemberCallExpr*) { return ""; }

std::unique_ptr<KernelPrinter> GlslPrinter::Sibling(const CXXRecordDecl* cls) const { return std::make_unique<GlslPrinter>(m_ctx, cls, m_reporter); }

}  // namespace crossrt::engine
