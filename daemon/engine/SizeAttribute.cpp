// Teaches Clang the size annotation of control-function pointer parameters, in both spellings:
//   const float* in __attribute__((size("n")))      [[crossrt::size("n")]] const float* in
// The element-count expression is kept on the parameter as an AnnotateAttr "crossrt.size=<expr>".
#include <clang/AST/ASTContext.h>
#include <clang/AST/Attr.h>
#include <clang/Basic/SourceManager.h>
#include <clang/Sema/ParsedAttr.h>
#include <clang/Sema/Sema.h>

#include <cstring>
#include <string>

using namespace clang;

namespace {

struct SizeAttrInfo : ParsedAttrInfo {
  SizeAttrInfo() {
    static constexpr Spelling spellings[] = {{ParsedAttr::AS_GNU, "size"}, {ParsedAttr::AS_CXX11, "crossrt::size"}};
    Spellings = spellings;
    OptArgs = 1;
  }
  bool diagAppertainsToDecl(Sema& sema, const ParsedAttr& attr, const Decl* decl) const override {
    if (isa<ParmVarDecl>(decl)) return true;
    sema.Diag(attr.getLoc(), diag::warn_attribute_wrong_decl_type_str) << attr << attr.isRegularKeywordAttribute() << "parameters";
    return false;
  }
  AttrHandling handleDeclAttribute(Sema& sema, Decl* decl, const ParsedAttr& attr) const override {
    std::string expr;
    if (attr.getNumArgs() == 1)
      if (auto* str = dyn_cast<StringLiteral>(attr.getArgAsExpr(0)->IgnoreParenCasts())) expr = str->getString().str();
    if (expr.empty()) {
      // Clang does not parse the arguments of scoped plugin attributes: read the quoted text.
      const char* text = sema.getSourceManager().getCharacterData(attr.getLoc());
      std::string rest(text, strnlen(text, 1024));
      auto q1 = rest.find('"'), q2 = q1 == std::string::npos ? q1 : rest.find('"', q1 + 1), close = rest.find(')');
      if (q2 == std::string::npos || q2 > rest.find(']') || q1 > close) {
        unsigned id = sema.getDiagnostics().getCustomDiagID(DiagnosticsEngine::Error,
            "size annotation needs the element count as a string, e.g. [[crossrt::size(\"n\")]]");
        sema.Diag(attr.getLoc(), id);
        return AttributeNotApplied;
      }
      expr = rest.substr(q1 + 1, q2 - q1 - 1);
    }
    decl->addAttr(AnnotateAttr::Create(sema.Context, "crossrt.size=" + expr, nullptr, 0, attr.getRange()));
    return AttributeApplied;
  }
};

}  // namespace

static ParsedAttrInfoRegistry::Add<SizeAttrInfo> registerSize("crossrt-size", "element count of a pointer parameter");

// Referenced by the translator so that the linker keeps this file's registration.
namespace crossrt::engine {
void LinkSizeAttribute() {}
}  // namespace crossrt::engine
