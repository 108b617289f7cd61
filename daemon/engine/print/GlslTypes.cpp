// C++ types as GLSL sees them: the GLSL spelling of LiteMath and the user's types, what images,
// samplers, textures and vectors hold, and the std430 and scalar layouts a buffer may use to match
// the C++ layout exactly. Takes Clang types; prints nothing.
#include "print/GlslTypes.h"

#include <clang/AST/RecordLayout.h>
#include <clang/Basic/SourceManager.h>
#include <clang/Lex/Lexer.h>

#include <cstdio>
#include <map>
#include <set>

using namespace clang;

namespace crossrt::engine {

namespace {

const char* LiteMathGlsl(StringRef name) {
  static const std::map<std::string, const char*> table = {
      {"float2", "vec2"},  {"float3", "vec3"},  {"float4", "vec4"},  {"int2", "ivec2"},
      {"int3", "ivec3"},   {"int4", "ivec4"},   {"uint2", "uvec2"},  {"uint3", "uvec3"},
      {"uint4", "uvec4"},  {"float3x3", "mat3"}, {"float4x4", "mat4"},
      // 16-bit floats in storage: two per uint (packHalf2x16), converted to float to compute.
      {"half2", "uint"},   {"half4", "uvec2"}};
  auto it = table.find(name.str());
  return it == table.end() ? nullptr : it->second;
}

}  // namespace

bool InNamespace(const Decl* d, const char* ns) {
  for (auto* dc = d->getDeclContext(); dc; dc = dc->getParent())
    if (auto* nsd = dyn_cast<NamespaceDecl>(dc); nsd && nsd->getName() == ns) return true;
  return false;
}
std::string DoubleRefusal(const std::string& type) {
  return "type '" + type + "' is not supported in Vulkan kernels: many GPUs have no 64-bit floats, the others run them many times slower";
}
std::string DoubleRefusalHint() {
  return "use float (literals such as 0.5 are fine: they become float), or translate the class with BACKEND cpu, which runs it as written";
}

bool IsSystemDecl(const Decl* decl) {
  auto& sm = decl->getASTContext().getSourceManager();
  return sm.isInSystemHeader(sm.getExpansionLoc(decl->getLocation()));
}

bool IsLiteMathType(QualType type, const char* name) {
  auto* rd = type.getCanonicalType()->getAsCXXRecordDecl();
  if (!rd || !InNamespace(rd, "LiteMath")) return false;
  return name ? rd->getName() == name : LiteMathGlsl(rd->getName()) != nullptr;
}

bool IsStdVector(QualType type, QualType* element) {
  auto* spec = dyn_cast_or_null<ClassTemplateSpecializationDecl>(type.getCanonicalType()->getAsCXXRecordDecl());
  if (!spec || spec->getName() != "vector" || !spec->isInStdNamespace()) return false;
  if (element) *element = spec->getTemplateArgs()[0].getAsType();
  return true;
}

bool IsStdArray(QualType type, QualType* element, uint64_t* size) {
  auto* spec = dyn_cast_or_null<ClassTemplateSpecializationDecl>(type.getNonReferenceType().getCanonicalType()->getAsCXXRecordDecl());
  if (!spec || spec->getName() != "array" || !spec->isInStdNamespace() || spec->getTemplateArgs().size() != 2) return false;
  if (element) *element = spec->getTemplateArgs()[0].getAsType();
  if (size) *size = spec->getTemplateArgs()[1].getAsIntegral().getZExtValue();
  return true;
}

bool IsImage2D(QualType type, QualType* texel) {
  auto* spec = dyn_cast_or_null<ClassTemplateSpecializationDecl>(type.getNonReferenceType().getCanonicalType()->getAsCXXRecordDecl());
  if (!spec || spec->getName() != "Image2D" || spec->getTemplateArgs().size() != 1) return false;
  if (texel) *texel = spec->getTemplateArgs()[0].getAsType();
  return true;
}

bool IsImageSampler(QualType type) {
  auto* rd = type.getNonReferenceType().getCanonicalType()->getAsCXXRecordDecl();
  return rd && rd->getName() == "Sampler" && InNamespace(rd, "LiteImage");
}

bool IsCombinedSamplerPointer(QualType type) {
  type = type.getNonReferenceType().getCanonicalType();
  const CXXRecordDecl* pointee = nullptr;
  if (type->isPointerType()) pointee = type->getPointeeType()->getAsCXXRecordDecl();
  else if (auto* spec = dyn_cast_or_null<ClassTemplateSpecializationDecl>(type->getAsCXXRecordDecl());
           spec && spec->isInStdNamespace() && (spec->getName() == "shared_ptr" || spec->getName() == "unique_ptr"))
    pointee = spec->getTemplateArgs()[0].getAsType()->getAsCXXRecordDecl();
  return pointee && pointee->getName() == "ICombinedImageSampler" && InNamespace(pointee, "LiteImage");
}

bool IsCombinedSamplers(QualType type, bool* single) {
  QualType elem;
  const bool vector = IsStdVector(type.getNonReferenceType(), &elem);
  if (single) *single = !vector;
  return IsCombinedSamplerPointer(vector ? elem : type);
}

std::optional<ImageFormat> TextureArrayFormat(QualType type) {
  if (IsCombinedSamplers(type)) return ImageFormat{"rgba32f", "VK_FORMAT_R32G32B32A32_SFLOAT", "vec4", ""};
  QualType texel;
  if (!IsTextureArray(type, &texel)) return std::nullopt;
  return ImageFormatOf(texel);
}

bool IsTextureArray(QualType type, QualType* texel) {
  if (IsCombinedSamplers(type)) return true;
  QualType elem;
  if (!IsStdVector(type.getNonReferenceType(), &elem)) return false;
  auto* spec = dyn_cast_or_null<ClassTemplateSpecializationDecl>(elem.getCanonicalType()->getAsCXXRecordDecl());
  if (!spec || spec->getName() != "Texture2D" || spec->getTemplateArgs().size() != 1 || !InNamespace(spec, "LiteImage")) return false;
  if (texel) *texel = spec->getTemplateArgs()[0].getAsType();
  return true;
}

std::optional<ImageFormat> ImageFormatOf(QualType texel) {
  texel = texel.getCanonicalType().getUnqualifiedType();
  if (IsLiteMathType(texel, "float4")) return ImageFormat{"rgba32f", "VK_FORMAT_R32G32B32A32_SFLOAT", "vec4", ""};
  if (texel->isSpecificBuiltinType(BuiltinType::Float)) return ImageFormat{"r32f", "VK_FORMAT_R32_SFLOAT", "float", ""};
  if (texel->isSpecificBuiltinType(BuiltinType::UInt)) return ImageFormat{"r32ui", "VK_FORMAT_R32_UINT", "uint", "u"};
  return std::nullopt;
}

std::optional<std::string> GlslTypeOf(QualType type) {
  type = type.getNonReferenceType().getCanonicalType().getUnqualifiedType();
  if (auto* arr = dyn_cast<ConstantArrayType>(type.getTypePtr())) {
    auto elem = GlslTypeOf(arr->getElementType());
    if (!elem) return std::nullopt;
    return *elem + "[" + std::to_string(arr->getSize().getZExtValue()) + "]";
  }
  if (auto* bt = type->getAs<BuiltinType>()) {
    switch (bt->getKind()) {
      case BuiltinType::Void: return "void";
      case BuiltinType::Bool: return "bool";
      case BuiltinType::Float: return "float";
      case BuiltinType::Char_S: case BuiltinType::SChar: case BuiltinType::Short:
      case BuiltinType::Int: case BuiltinType::Long: case BuiltinType::LongLong:
        return "int";  // 64-bit integers become 32-bit: shader buffers cannot exceed 4 GiB anyway
      case BuiltinType::Char_U: case BuiltinType::UChar: case BuiltinType::UShort:
      case BuiltinType::UInt: case BuiltinType::ULong: case BuiltinType::ULongLong:
        return "uint";
      default: return std::nullopt;  // double and friends: reported by the caller
    }
  }
  if (auto* et = type->getAs<EnumType>()) return GlslTypeOf(et->getDecl()->getIntegerType());
  QualType element;
  uint64_t size = 0;
  if (IsStdArray(type, &element, &size)) {  // as T[N]
    auto elem = GlslTypeOf(element);
    if (!elem) return std::nullopt;
    return *elem + "[" + std::to_string(size) + "]";
  }
  if (auto* rd = type->getAsCXXRecordDecl()) {
    if (InNamespace(rd, "LiteMath"))
      if (auto* g = LiteMathGlsl(rd->getName())) return std::string(g);
    // Other LiteMath records (Box4f) are plain structs like the user's.
    if (IsSystemDecl(rd) || rd->isUnion() || rd->isPolymorphic() || rd->getName().empty()) return std::nullopt;
    return rd->getName().str();
  }
  return std::nullopt;
}

unsigned Std430VectorStride(const std::string& glslType) {
  std::string base = SplitArray(glslType).first;
  if (base == "float" || base == "int" || base == "uint" || base == "bool") return 4;
  if (base.size() >= 4 && base.compare(base.size() - 4, 4, "vec2") == 0) return 8;
  return 16;
}

std::pair<std::string, std::string> SplitArray(const std::string& glslType) {
  auto pos = glslType.find('[');
  if (pos == std::string::npos) return {glslType, ""};
  return {glslType.substr(0, pos), glslType.substr(pos)};
}

// std430 (or scalar) size and alignment, following the GLSL specification's rules.
std::optional<LayoutInfo> Std430Layout(ASTContext& ctx, QualType type, bool scalar) {
  type = type.getCanonicalType().getUnqualifiedType();
  auto roundUp = [](uint64_t v, uint64_t a) { return (v + a - 1) / a * a; };
  if (auto* arr = dyn_cast<ConstantArrayType>(type.getTypePtr())) {
    auto e = Std430Layout(ctx, arr->getElementType(), scalar);
    if (!e) return std::nullopt;
    uint64_t stride = scalar ? e->size : roundUp(e->size, e->align);
    return LayoutInfo{stride * arr->getSize().getZExtValue(), e->align};
  }
  if (auto* bt = type->getAs<BuiltinType>()) {
    if (bt->isFloatingPoint() && bt->getKind() != BuiltinType::Float) return std::nullopt;
    if (bt->getKind() == BuiltinType::Bool) return std::nullopt;  // 1 byte in C++, 4 in GLSL
    if (ctx.getTypeSize(type) != 32) return std::nullopt;         // only 32-bit scalars are shared
    return LayoutInfo{4, 4};
  }
  if (auto* et = type->getAs<EnumType>()) return Std430Layout(ctx, et->getDecl()->getIntegerType(), scalar);
  auto* rd = type->getAsCXXRecordDecl();
  if (!rd) return std::nullopt;
  if (InNamespace(rd, "LiteMath") && LiteMathGlsl(rd->getName())) {
    auto name = rd->getName();
    int n = name.ends_with("2") ? 2 : name.ends_with("3") ? 3 : name.ends_with("4") ? 4 : 0;
    if (name == "float3x3") return scalar ? LayoutInfo{36, 4} : LayoutInfo{48, 16};
    if (name == "half2") return LayoutInfo{4, 4};
    if (name == "half4") return scalar ? LayoutInfo{8, 4} : LayoutInfo{8, 8};
    if (name == "float4x4") return scalar ? LayoutInfo{64, 4} : LayoutInfo{64, 16};
    if (!LiteMathGlsl(name) || n == 0) return std::nullopt;
    if (scalar) return LayoutInfo{uint64_t(4 * n), 4};
    return LayoutInfo{uint64_t(4 * n), n == 2 ? 8u : 16u};
  }
  if (rd->isPolymorphic() || rd->isUnion()) return std::nullopt;
  uint64_t offset = 0, align = 4;
  for (auto* f : rd->fields()) {
    auto fl = Std430Layout(ctx, f->getType(), scalar);
    if (!fl) return std::nullopt;
    offset = roundUp(offset, fl->align) + fl->size;
    align = std::max(align, fl->align);
  }
  return LayoutInfo{roundUp(offset, align), align};
}

bool LayoutMatchesCpp(ASTContext& ctx, QualType type, bool scalar) {
  type = type.getCanonicalType().getUnqualifiedType();
  auto gl = Std430Layout(ctx, type, scalar);
  if (!gl) return false;
  uint64_t cppSize = ctx.getTypeSizeInChars(type).getQuantity();
  uint64_t stride = scalar ? gl->size : (gl->size + gl->align - 1) / gl->align * gl->align;
  if (stride != cppSize) return false;
  // Field offsets of user structs must agree too.
  auto* rd = type->getAsCXXRecordDecl();
  if (!rd || IsLiteMathType(type, nullptr)) return true;
  const ASTRecordLayout& cpp = ctx.getASTRecordLayout(rd);
  uint64_t offset = 0;
  for (auto* f : rd->fields()) {
    auto fl = Std430Layout(ctx, f->getType(), scalar);
    offset = (offset + fl->align - 1) / fl->align * fl->align;
    if (cpp.getFieldOffset(f->getFieldIndex()) / 8 != offset) return false;
    // A nested struct must match inside too; a nested LiteMath vector matched by size and offset
    // (its array stride, which differs for vec3, does not apply to a field).
    if (f->getType()->getAsCXXRecordDecl() && !IsLiteMathType(f->getType()) && !LayoutMatchesCpp(ctx, f->getType(), scalar)) return false;
    offset += fl->size;
  }
  return true;
}

}  // namespace crossrt::engine
