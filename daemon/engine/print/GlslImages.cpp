// The printer's images: Image2D members and parameters as storage images (texels loaded and
// stored) or textures (sampled with a LiteImage::Sampler), and arrays of textures. Part of
// GlslPrinter (Glsl.h).
#include "print/Glsl.h"
#include "print/GlslParts.h"

#include <clang/AST/RecordLayout.h>
#include <clang/Basic/SourceManager.h>
#include <clang/Lex/Lexer.h>

#include <cstdio>
#include <map>
#include <set>

using namespace clang;

namespace crossrt::engine {

// ---- Image2D members and parameters: storage images (texels loaded and stored) and textures (sampled) ----

const FieldDecl* ThisMemberField(const clang::Expr* e) {
  auto* me = dyn_cast<MemberExpr>(e->IgnoreParenImpCasts());
  if (!me || !isa<CXXThisExpr>(me->getBase()->IgnoreParenImpCasts())) return nullptr;
  return dyn_cast<FieldDecl>(me->getMemberDecl());
}

// How a texel of the image's type becomes the C++ value: images hold 4 channels on the GPU.
std::string TexelOf(const ImageFormat& f, const std::string& load) { return f.texel == "vec4" ? load : load + ".x"; }

// How GLSL names an image's storage image: a member by its name, a parameter by its name made safe
// for GLSL. Its texture and size add "_texture", "_width", "_height" to the name as written.
std::string ImageName(const ValueDecl* image) {
  return isa<FieldDecl>(image) ? image->getNameAsString() : GlslPrinter::SafeName(image->getNameAsString());
}
std::string Described(const ValueDecl* image) {
  return std::string(isa<FieldDecl>(image) ? "Image2D member '" : "Image2D parameter '") + image->getNameAsString() + "'";
}

const ValueDecl* GlslPrinter::ImageOf(const clang::Expr* e) const {
  if (auto* f = ThisMemberField(e); f && IsImage2D(f->getType())) return f;
  if (auto* dr = dyn_cast<DeclRefExpr>(e->IgnoreParenImpCasts()); dr && imageParams.count(dr->getDecl())) return dr->getDecl();
  return nullptr;
}

// The image of a texel expression (img[p], img.at(x, y)), or null; prints the coordinate into
// `coord` when given.
const ValueDecl* GlslPrinter::ImageTexel(const clang::Expr* e, std::string* coord) {
  e = e->IgnoreParenImpCasts();
  if (auto* op = dyn_cast<CXXOperatorCallExpr>(e); op && op->getOperator() == OO_Subscript) {
    auto* image = ImageOf(op->getArg(0));
    if (!image) return nullptr;
    // int2 is ivec2 already; uint2 and friends are converted.
    const bool ivec = GlslTypeOf(op->getArg(1)->getType()).value_or("") == "ivec2";
    if (coord) *coord = ivec ? Expr(op->getArg(1)) : "ivec2(" + Expr(op->getArg(1)) + ")";
    return image;
  }
  if (auto* mc = dyn_cast<CXXMemberCallExpr>(e); mc && mc->getMethodDecl() && mc->getMethodDecl()->getName() == "at" && mc->getNumArgs() == 2) {
    auto* image = ImageOf(mc->getImplicitObjectArgument());
    if (!image) return nullptr;
    if (coord) *coord = "ivec2(" + Expr(mc->getArg(0)) + ", " + Expr(mc->getArg(1)) + ")";
    return image;
  }
  return nullptr;
}

std::optional<ImageFormat> GlslPrinter::UsableImage(const ValueDecl* image, SourceLocation use) {
  QualType texel;
  IsImage2D(image->getType().getNonReferenceType(), &texel);
  auto format = ImageFormatOf(texel);
  if (!format)
    Fail(use, Described(image) + " has a texel type GPU images cannot hold ('" + texel.getAsString(m_ctx.getPrintingPolicy()) + "')",
         "use Image2D<float4>, Image2D<float> or Image2D<uint32_t>");
  else if (!composedPrefix.empty() || selfClass)
    Fail(use, Described(image) + " used outside the class's own kernels", "use images only in kernels and helpers of the translated class");
  else
    return format;
  return std::nullopt;
}

// The sampler member of img.sample(sampler, uv), recorded as used with the image; null (reported)
// for an image of uint32_t, which samplers do not filter, or a sampler that is not a member.
const FieldDecl* GlslPrinter::SampledWith(const ValueDecl* image, const ImageFormat& format, const CXXMemberCallExpr* call) {
  if (format.texel == "uint") {
    Fail(call->getBeginLoc(), "sample() of Image2D<uint32_t> " + std::string(isa<FieldDecl>(image) ? "member" : "parameter") + " '" +
         image->getNameAsString() + "' (samplers filter only float images)",
         "read texels with " + image->getNameAsString() + "[int2(x, y)], or store the image as Image2D<float> or Image2D<float4>");
    return nullptr;
  }
  const FieldDecl* sampler = ThisMemberField(call->getArg(0));
  if (!sampler || !IsImageSampler(sampler->getType())) {
    Fail(call->getArg(0)->getBeginLoc(), "the sampler of " + image->getNameAsString() + ".sample() is not a member of the class",
         "declare the LiteImage::Sampler as a member, so it is created on the GPU with the image");
    return nullptr;
  }
  m_uses.sampledImages.insert(image);
  m_uses.samplers.insert(sampler);
  m_uses.samplePairs.insert({image, sampler});
  return sampler;
}

std::string GlslPrinter::ImageStore(const clang::Expr* lhs, const std::string& value, const clang::Expr* whole) {
  std::string coord;
  const ValueDecl* image = ImageTexel(lhs, &coord);
  auto format = UsableImage(image, whole->getBeginLoc());
  if (!format) return "/*error*/";
  m_uses.storedImages.insert(image);
  const std::string channels = format->prefix + "vec4";
  return "imageStore(" + ImageName(image) + ", " + coord + ", " + (format->texel == "vec4" ? value : channels + "(" + value + ")") + ")";
}

std::string GlslPrinter::ImageCall(const ValueDecl* image, const CXXMemberCallExpr* call) {
  const std::string name = ImageName(image);
  const std::string method = call->getMethodDecl()->getNameAsString();
  auto format = UsableImage(image, call->getBeginLoc());
  if (!format) return "/*error*/";
  if (method == "width" || method == "height") {
    m_uses.sizedImages.insert(image);
    return image->getNameAsString() + "_" + method;
  }
  if (method == "at") {
    std::string coord;
    ImageTexel(call, &coord);
    m_uses.loadedImages.insert(image);
    return TexelOf(*format, "imageLoad(" + name + ", " + coord + ")");
  }
  if (method == "set" && call->getNumArgs() == 3) {
    m_uses.storedImages.insert(image);
    const std::string value = Expr(call->getArg(2));
    return "imageStore(" + name + ", ivec2(" + Expr(call->getArg(0)) + ", " + Expr(call->getArg(1)) + "), " +
           (format->texel == "vec4" ? value : format->prefix + "vec4(" + value + ")") + ")";
  }
  if (method == "sample" && call->getNumArgs() == 2) {
    const FieldDecl* sampler = SampledWith(image, *format, call);
    if (!sampler) return "/*error*/";
    // Compute shaders have no derivatives: sample the one mip level explicitly.
    return TexelOf(*format, "textureLod(sampler2D(" + image->getNameAsString() + "_texture, " + sampler->getNameAsString() + "), " + Expr(call->getArg(1)) + ", 0.0)");
  }
  return Fail(call->getBeginLoc(), "Image2D::" + method + " is not supported in kernels",
              "kernels read texels (" + image->getNameAsString() + "[p], at(x, y), sample(sampler, uv)), write them (" + image->getNameAsString() +
              "[p] = v, set(x, y, v)) and read width() and height()");
}

// ---- arrays of textures: std::vector<LiteImage::Texture2D<T>> members ----
// Kernels call <array>_sample, _texel, _width and _height (templates/glsl/texture_array.glsl), which
// each variant of the shader defines its own way: GPU samplers, or buffers and LiteImage's sampling.

const FieldDecl* GlslPrinter::TextureElement(const clang::Expr* e, const clang::Expr** index) {
  auto* op = dyn_cast<CXXOperatorCallExpr>(e->IgnoreParenImpCasts());
  if (!op || op->getOperator() != OO_Subscript) return nullptr;
  auto* f = ThisMemberField(op->getArg(0));
  if (!f || !IsTextureArray(f->getType())) return nullptr;
  if (index) *index = op->getArg(1);
  return f;
}

bool GlslPrinter::UsableTextures(const FieldDecl* array, SourceLocation use) {
  QualType texel;
  IsTextureArray(array->getType(), &texel);
  auto format = ImageFormatOf(texel);
  if (!format || format->texel == "uint")
    Fail(use, "array of textures '" + array->getNameAsString() + "' has a texel type GPU samplers cannot filter ('" +
         texel.getAsString(m_ctx.getPrintingPolicy()) + "')", "use LiteImage::Texture2D<float4> or Texture2D<float>");
  else if (!composedPrefix.empty() || selfClass)
    Fail(use, "array of textures '" + array->getNameAsString() + "' used outside the class's own kernels",
         "use textures only in kernels and helpers of the translated class; pass a texture index to the object instead");
  else {
    m_uses.textureArrays.insert(array);
    return true;
  }
  return false;
}

namespace {
// A texture index as the generated functions take it (uint).
std::string TextureIndex(const clang::Expr* index, const std::string& printed) {
  return index->getType()->isUnsignedIntegerType() ? printed : "uint(" + printed + ")";
}
}  // namespace

std::string GlslPrinter::TextureCall(const FieldDecl* array, const clang::Expr* index, const CXXMemberCallExpr* call) {
  const std::string name = array->getNameAsString();
  const std::string method = call->getMethodDecl()->getNameAsString();
  if (!UsableTextures(array, call->getBeginLoc())) return "/*error*/";
  const std::string i = TextureIndex(index, Expr(index));
  if (method == "sample" && call->getNumArgs() == 1) return name + "_sample(" + i + ", " + Expr(call->getArg(0)) + ")";
  if ((method == "width" || method == "height") && call->getNumArgs() == 0) return name + "_" + method + "(" + i + ")";
  return Fail(call->getBeginLoc(), "Texture2D::" + method + " is not supported in kernels",
              "kernels sample textures of an array (" + name + "[i].sample(uv)), read texels (" + name + "[i][p]) and read width() and height()");
}

std::string GlslPrinter::TextureTexel(const FieldDecl* array, const clang::Expr* index, const clang::Expr* coord, SourceLocation loc) {
  if (!UsableTextures(array, loc)) return "/*error*/";
  const bool ivec = GlslTypeOf(coord->getType()).value_or("") == "ivec2";
  return array->getNameAsString() + "_texel(" + TextureIndex(index, Expr(index)) + ", " + (ivec ? Expr(coord) : "ivec2(" + Expr(coord) + ")") + ")";
}

}  // namespace crossrt::engine

namespace crossrt::engine {

// ---- ISPC: Image2D members and parameters as LiteMath.isph's crt_Image_<T> (the C++ image's texels) ----

// The image as the ISPC kernels reach it: a member through `self`, a parameter by its name.
std::string GlslPrinter::IspcImage(const ValueDecl* image) const {
  return isa<FieldDecl>(image) ? IspcMember(image->getNameAsString()) : SafeName(image->getNameAsString());
}

// A texel (img[p] or img.at(x, y)) as an ISPC lvalue: the element of the C++ image's texels.
std::string GlslPrinter::IspcTexel(const clang::Expr* e) {
  e = e->IgnoreParenImpCasts();
  const ValueDecl* image = ImageTexel(e);
  if (!image || !UsableImage(image, e->getBeginLoc())) return "/*error*/";
  std::string x, y;
  if (auto* op = dyn_cast<CXXOperatorCallExpr>(e)) {
    const clang::Expr* p = op->getArg(1);
    const clang::Expr* bare = p->IgnoreImplicit();
    if (auto* fc = dyn_cast<CXXFunctionalCastExpr>(bare)) bare = fc->getSubExpr()->IgnoreImplicit();
    if (auto* ctor = dyn_cast<CXXConstructExpr>(bare); ctor && ctor->getNumArgs() == 2 && ctor->getArg(0)->getType()->isIntegerType() &&
                                                       ctor->getArg(1)->getType()->isIntegerType()) {  // img[int2(x, y)]
      const std::string img = IspcImage(image);
      return img + ".data[crt_texel(" + img + ".width, " + Expr(ctor->getArg(0)) + ", " + Expr(ctor->getArg(1)) + ")]";
    }
    if (p->HasSideEffects(m_ctx, /*IncludePossibleEffects=*/false))  // its x and y are read apart
      return Fail(p->getBeginLoc(), "a texel coordinate with side effects in an ISPC kernel", "compute the coordinate into a variable first");
    const std::string point = "(" + Expr(p) + ")";
    const bool signedInt = GlslTypeOf(p->getType()).value_or("") == "ivec2";
    x = signedInt ? point + ".x" : "(int)(" + point + ".x)";
    y = signedInt ? point + ".y" : "(int)(" + point + ".y)";
  } else {
    auto* mc = cast<CXXMemberCallExpr>(e);
    x = Expr(mc->getArg(0));
    y = Expr(mc->getArg(1));
  }
  const std::string img = IspcImage(image);
  return img + ".data[crt_texel(" + img + ".width, " + x + ", " + y + ")]";
}

std::string GlslPrinter::IspcImageCall(const ValueDecl* image, const CXXMemberCallExpr* call) {
  const std::string method = call->getMethodDecl()->getNameAsString(), img = IspcImage(image);
  auto format = UsableImage(image, call->getBeginLoc());
  if (!format) return "/*error*/";
  if ((method == "width" || method == "height") && call->getNumArgs() == 0) {
    m_uses.sizedImages.insert(image);
    return img + "." + method;
  }
  if (method == "at" && call->getNumArgs() == 2) {
    m_uses.loadedImages.insert(image);
    return IspcTexel(call);
  }
  if (method == "set" && call->getNumArgs() == 3) {
    m_uses.storedImages.insert(image);
    return img + ".data[crt_texel(" + img + ".width, " + Expr(call->getArg(0)) + ", " + Expr(call->getArg(1)) + ")] = " + Expr(call->getArg(2));
  }
  if (method == "sample" && call->getNumArgs() == 2) {
    const FieldDecl* sampler = SampledWith(image, *format, call);
    if (!sampler) return "/*error*/";
    return "crt_sample(" + img + ", " + IspcMember(sampler->getNameAsString()) + ", " + Expr(call->getArg(1)) + ")";  // LiteMath.isph
  }
  return Fail(call->getBeginLoc(), "Image2D::" + method + " is not supported in kernels",
              "kernels read texels (" + image->getNameAsString() + "[p], at(x, y), sample(sampler, uv)), write them (" + image->getNameAsString() +
              "[p] = v, set(x, y, v)) and read width() and height()");
}

}  // namespace crossrt::engine

namespace crossrt::engine {

// ---- ISPC: arrays of textures as LiteMath.isph's crt_Texture_<T> array (each texture's texels and sampler) ----

std::string GlslPrinter::IspcTextureCall(const FieldDecl* array, const clang::Expr* index, const CXXMemberCallExpr* call) {
  const std::string method = call->getMethodDecl()->getNameAsString();
  if (!UsableTextures(array, call->getBeginLoc())) return "/*error*/";
  const std::string texture = IspcMember(array->getNameAsString()) + "[" + Expr(index) + "]";
  if (method == "sample" && call->getNumArgs() == 1) return "crt_sample(" + texture + ", " + Expr(call->getArg(0)) + ")";  // LiteMath.isph
  if ((method == "width" || method == "height") && call->getNumArgs() == 0) return texture + "." + method;
  return Fail(call->getBeginLoc(), "Texture2D::" + method + " is not supported in kernels",
              "kernels sample textures of an array (" + array->getNameAsString() + "[i].sample(uv)), read texels (" + array->getNameAsString() +
              "[i][p]) and read width() and height()");
}

std::string GlslPrinter::IspcTextureTexel(const FieldDecl* array, const clang::Expr* index, const clang::Expr* coord, SourceLocation loc) {
  if (!UsableTextures(array, loc)) return "/*error*/";
  if (coord->HasSideEffects(m_ctx, /*IncludePossibleEffects=*/false))
    return Fail(coord->getBeginLoc(), "a texel coordinate with side effects in an ISPC kernel", "compute the coordinate into a variable first");
  const std::string p = "(" + Expr(coord) + ")";
  return "crt_texel_of(" + IspcMember(array->getNameAsString()) + "[" + Expr(index) + "], (int)(" + p + ".x), (int)(" + p + ".y))";
}

}  // namespace crossrt::engine
