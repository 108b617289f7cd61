// GLSL's images: Image2D members and parameters as storage images (imageLoad, imageStore) or as
// textures sampled with a LiteImage::Sampler, and arrays of textures (descriptor indexing).
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

namespace {
// A texture index as the generated functions take it (uint).
std::string TextureIndex(const clang::Expr* index, const std::string& printed) {
  if (!index) return "0u";  // the one texture of an ICombinedImageSampler pointer
  return index->getType()->isUnsignedIntegerType() ? printed : "uint(" + printed + ")";
}
}  // namespace

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
    return generated::ImageSizeField(image->getNameAsString(), method);
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
    return TexelOf(*format, "textureLod(sampler2D(" + generated::TextureName(image->getNameAsString()) + ", " + sampler->getNameAsString() + "), " + Expr(call->getArg(1)) + ", 0.0)");
  }
  return Fail(call->getBeginLoc(), "Image2D::" + method + " is not supported in kernels",
              "kernels read texels (" + image->getNameAsString() + "[p], at(x, y), sample(sampler, uv)), write them (" + image->getNameAsString() +
              "[p] = v, set(x, y, v)) and read width() and height()");
}

std::string GlslPrinter::TextureCall(const FieldDecl* array, const clang::Expr* index, const CXXMemberCallExpr* call) {
  const std::string name = array->getNameAsString();
  const std::string method = call->getMethodDecl()->getNameAsString();
  if (!UsableTextures(array, call->getBeginLoc())) return "/*error*/";
  const std::string i = TextureIndex(index, index ? Expr(index) : "");
  if (method == "sample" && call->getNumArgs() == 1) return "crt_" + name + "_sample(" + i + ", " + Expr(call->getArg(0)) + ")";
  if ((method == "width" || method == "height") && call->getNumArgs() == 0) return "crt_" + name + "_" + method + "(" + i + ")";
  return Fail(call->getBeginLoc(), call->getMethodDecl()->getParent()->getNameAsString() + "::" + method + " is not supported in kernels",
              "kernels sample textures of an array (" + name + "[i].sample(uv)), read texels (" + name + "[i][p]) and read width() and height()");
}

std::string GlslPrinter::TextureTexel(const FieldDecl* array, const clang::Expr* index, const clang::Expr* coord, SourceLocation loc) {
  if (!UsableTextures(array, loc)) return "/*error*/";
  const bool ivec = GlslTypeOf(coord->getType()).value_or("") == "ivec2";
  return "crt_" + array->getNameAsString() + "_texel(" + TextureIndex(index, index ? Expr(index) : "") + ", " + (ivec ? Expr(coord) : "ivec2(" + Expr(coord) + ")") + ")";
}

std::string GlslPrinter::TexelRead(const CXXOperatorCallExpr* op, const ValueDecl* image) {
  std::string coord;
  ImageTexel(op, &coord);
  auto format = UsableImage(image, op->getBeginLoc());
  if (!format) return "/*error*/";
  m_uses.loadedImages.insert(image);
  return TexelOf(*format, "imageLoad(" + ImageName(image) + ", " + coord + ")");
}

// A texel assigned through an operator of LiteMath's types: imageStore of the whole texel.
std::string GlslPrinter::TexelAssignment(const CXXOperatorCallExpr* op) {
  if (!op->isAssignmentOp() || op->getNumArgs() != 2 || !ImageTexel(op->getArg(0))) return "";
  const auto kind = op->getOperator();
  const clang::Expr* e = op;
  if (kind == OO_Equal) return ImageStore(op->getArg(0), Expr(op->getArg(1)), e);
  if (op->getArg(0)->HasSideEffects(m_ctx, /*IncludePossibleEffects=*/false))  // it is printed twice
    return Fail(e->getBeginLoc(), "compound assignment to a texel whose coordinate has side effects", "compute the coordinate into a variable first");
  std::string spelling = getOperatorSpelling(kind);
  return ImageStore(op->getArg(0), Expr(op->getArg(0)) + " " + spelling.substr(0, spelling.size() - 1) + " (" + Expr(op->getArg(1)) + ")", e);
}

}  // namespace crossrt::engine
