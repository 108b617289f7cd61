// The printer's images: Image2D members and parameters as storage images (texels loaded and
// stored) or textures (sampled with a LiteImage::Sampler), and arrays of textures. Part of
// KernelPrinter (KernelPrinter.h): what an image expression is; how each language reads, stores and
// samples texels is its printer's (glsl/GlslImages.cpp, ispc/IspcImages.cpp).
#include "print/KernelPrinter.h"
#include "print/PrinterParts.h"

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
// for GLSL. Its texture and size are generated::TextureName and ImageSizeField of the name as written.
std::string ImageName(const ValueDecl* image) {
  return isa<FieldDecl>(image) ? image->getNameAsString() : KernelPrinter::SafeName(image->getNameAsString());
}
std::string Described(const ValueDecl* image) {
  return std::string(isa<FieldDecl>(image) ? "Image2D member '" : "Image2D parameter '") + image->getNameAsString() + "'";
}

const ValueDecl* KernelPrinter::ImageOf(const clang::Expr* e) const {
  if (auto* f = ThisMemberField(e); f && IsImage2D(f->getType())) return f;
  if (auto* dr = dyn_cast<DeclRefExpr>(e->IgnoreParenImpCasts()); dr && imageParams.count(dr->getDecl())) return dr->getDecl();
  return nullptr;
}

// The image of a texel expression (img[p], img.at(x, y)), or null; prints the coordinate into
// `coord` when given.
const ValueDecl* KernelPrinter::ImageTexel(const clang::Expr* e, std::string* coord) {
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

std::optional<ImageFormat> KernelPrinter::UsableImage(const ValueDecl* image, SourceLocation use) {
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
const FieldDecl* KernelPrinter::SampledWith(const ValueDecl* image, const ImageFormat& format, const CXXMemberCallExpr* call) {
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

// ---- arrays of textures: std::vector<LiteImage::Texture2D<T>> members ----
// Kernels call crt_<array>_sample, _texel, _width and _height (templates/glsl/texture_array.glsl), which
// each variant of the shader defines its own way: GPU samplers, or buffers and LiteImage's sampling.

// m_textures[i], m_samplers[i]-> (ICombinedImageSampler pointers) or m_pSampler-> (one: index null).
const FieldDecl* KernelPrinter::TextureElement(const clang::Expr* e, const clang::Expr** index) {
  e = e->IgnoreParenImpCasts();
  if (auto* arrow = dyn_cast<CXXOperatorCallExpr>(e); arrow && arrow->getOperator() == OO_Arrow) e = arrow->getArg(0)->IgnoreParenImpCasts();
  bool single = false;
  if (auto* f = ThisMemberField(e); f && IsCombinedSamplers(f->getType(), &single) && single) {
    if (index) *index = nullptr;
    return f;
  }
  auto* op = dyn_cast<CXXOperatorCallExpr>(e);
  if (!op || op->getOperator() != OO_Subscript) return nullptr;
  auto* f = ThisMemberField(op->getArg(0));
  if (!f || !IsTextureArray(f->getType())) return nullptr;
  if (index) *index = op->getArg(1);
  return f;
}

bool KernelPrinter::UsableTextures(const FieldDecl* array, SourceLocation use) {
  QualType texel;
  IsTextureArray(array->getType(), &texel);
  auto format = TextureArrayFormat(array->getType());
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

}  // namespace crossrt::engine
