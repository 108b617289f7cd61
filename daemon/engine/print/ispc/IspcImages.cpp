// ISPC's images: Image2D members and parameters as the class data's texel arrays (loads and stores
// alike, texels are lvalues), samples through LiteMath.isph, and arrays of textures.
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

// The image as the ISPC kernels reach it: a member through `self`, a parameter by its name.
std::string IspcPrinter::Image(const ValueDecl* image) const {
  return isa<FieldDecl>(image) ? Member(image->getNameAsString()) : SafeName(image->getNameAsString());
}

// A texel (img[p] or img.at(x, y)) as an ISPC lvalue: the element of the C++ image's texels.
std::string IspcPrinter::Texel(const clang::Expr* e) {
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
      const std::string img = Image(image);
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
  const std::string img = Image(image);
  return img + ".data[crt_texel(" + img + ".width, " + x + ", " + y + ")]";
}

std::string IspcPrinter::ImageCall(const ValueDecl* image, const CXXMemberCallExpr* call) {
  const std::string method = call->getMethodDecl()->getNameAsString(), img = Image(image);
  auto format = UsableImage(image, call->getBeginLoc());
  if (!format) return "/*error*/";
  if ((method == "width" || method == "height") && call->getNumArgs() == 0) {
    m_uses.sizedImages.insert(image);
    return img + "." + method;
  }
  if (method == "at" && call->getNumArgs() == 2) {
    m_uses.loadedImages.insert(image);
    return Texel(call);
  }
  if (method == "set" && call->getNumArgs() == 3) {
    m_uses.storedImages.insert(image);
    return img + ".data[crt_texel(" + img + ".width, " + Expr(call->getArg(0)) + ", " + Expr(call->getArg(1)) + ")] = " + Expr(call->getArg(2));
  }
  if (method == "sample" && call->getNumArgs() == 2) {
    const FieldDecl* sampler = SampledWith(image, *format, call);
    if (!sampler) return "/*error*/";
    return "crt_sample(" + img + ", " + Member(sampler->getNameAsString()) + ", " + Expr(call->getArg(1)) + ")";  // LiteMath.isph
  }
  return Fail(call->getBeginLoc(), "Image2D::" + method + " is not supported in kernels",
              "kernels read texels (" + image->getNameAsString() + "[p], at(x, y), sample(sampler, uv)), write them (" + image->getNameAsString() +
              "[p] = v, set(x, y, v)) and read width() and height()");
}

std::string IspcPrinter::TextureCall(const FieldDecl* array, const clang::Expr* index, const CXXMemberCallExpr* call) {
  const std::string method = call->getMethodDecl()->getNameAsString();
  if (!UsableTextures(array, call->getBeginLoc())) return "/*error*/";
  const std::string texture = Member(array->getNameAsString()) + "[" + (index ? Expr(index) : "0") + "]";  // one ICombinedImageSampler: 0
  if (method == "sample" && call->getNumArgs() == 1) return "crt_sample(" + texture + ", " + Expr(call->getArg(0)) + ")";  // LiteMath.isph
  if ((method == "width" || method == "height") && call->getNumArgs() == 0) return texture + "." + method;
  return Fail(call->getBeginLoc(), call->getMethodDecl()->getParent()->getNameAsString() + "::" + method + " is not supported in kernels",
              "kernels sample textures of an array (" + array->getNameAsString() + "[i].sample(uv)), read texels (" + array->getNameAsString() +
              "[i][p]) and read width() and height()");
}

std::string IspcPrinter::TextureTexel(const FieldDecl* array, const clang::Expr* index, const clang::Expr* coord, SourceLocation loc) {
  if (!UsableTextures(array, loc)) return "/*error*/";
  if (coord->HasSideEffects(m_ctx, /*IncludePossibleEffects=*/false))
    return Fail(coord->getBeginLoc(), "a texel coordinate with side effects in an ISPC kernel", "compute the coordinate into a variable first");
  const std::string p = "(" + Expr(coord) + ")";
  return "crt_texel_of(" + Member(array->getNameAsString()) + "[" + (index ? Expr(index) : "0") + "], (int)(" + p + ".x), (int)(" + p + ".y))";
}

std::string IspcPrinter::TexelRead(const CXXOperatorCallExpr* op, const ValueDecl* image) {
  m_uses.loadedImages.insert(image);  // (ISPC binds no images: loads and stores are alike)
  return Texel(op);
}

}  // namespace crossrt::engine
