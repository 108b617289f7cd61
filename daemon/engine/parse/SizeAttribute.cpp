// Teaches Clang the size annotation of control-function pointer parameters, in every spelling:
//   const float* in __attribute__((size("n")))    [[size("n")]] const float* in    [[crossrt::size("n")]] const float* in
// Several strings multiply (size("w", "h") is w * h elements, as in kernel_slicer); a number or a
// name may go without quotes (size(1), size(n)). The count is
// kept on the parameter as an AnnotateAttr "crossrt.size=<expr>".
#include <clang/AST/ASTContext.h>
#include <clang/AST/Attr.h>
#include <clang/Basic/SourceManager.h>
#include <clang/Sema/ParsedAttr.h>
#include <clang/Sema/Sema.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <string>
#include <vector>

using namespace clang;

namespace {

// The count a size annotation gives: its strings multiplied, as kernel_slicer reads them
// (size("w", "h", "4") is w * h * 4 elements). Each string is an expression of the parameters.
std::string SizeProduct(const std::vector<std::string>& factors) {
  auto simple = [](const std::string& f) {
    for (char c : f)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.')) return false;
    return true;
  };
  if (factors.size() == 1) return factors[0];
  std::string product;
  for (auto& f : factors) product += (product.empty() ? "" : " * ") + (simple(f) ? f : "(" + f + ")");
  return product;
}

// The arguments between the attribute's parentheses, read from the source text (Clang does not
// parse the arguments of C++11 plugin attributes): each string's contents, or the text of an
// argument written without quotes (size(1), size(n)). Empty when there are none.
std::vector<std::string> ArgumentTexts(Sema& sema, const ParsedAttr& attr) {
  const char* text = sema.getSourceManager().getCharacterData(attr.getLoc());
  std::string rest(text, strnlen(text, 4096));
  std::vector<std::string> args;
  size_t i = rest.find('(');
  if (i == std::string::npos || rest.find_first_of(";{]", 0) < i) return args;
  auto trimmed = [](std::string a) {
    const size_t b = a.find_first_not_of(" \t\n"), e = a.find_last_not_of(" \t\n");
    return b == std::string::npos ? std::string() : a.substr(b, e - b + 1);
  };
  int depth = 0;
  std::string current;
  bool quoted = false;
  for (; i < rest.size(); ++i) {
    const char c = rest[i];
    if (c == '"') {
      size_t end = i + 1;
      while (end < rest.size() && rest[end] != '"') end += rest[end] == '\\' ? 2 : 1;
      current = rest.substr(i + 1, end - i - 1);
      quoted = true;
      i = end;
      continue;
    }
    if (c == '(' && depth++ == 0) continue;
    if ((c == ')' && --depth == 0) || (c == ',' && depth == 1)) {
      args.push_back(quoted ? current : trimmed(current));
      current.clear();
      quoted = false;
      if (c == ')') break;
      continue;
    }
    if (!quoted) current += c;
  }
  return args;
}

struct SizeAttrInfo : ParsedAttrInfo {
  SizeAttrInfo() {
    // __attribute__((size("n"))) and [[size("n")]] as the paper and kernel_slicer write them;
    // [[crossrt::size("n")]], which GCC can be told to ignore quietly.
    static constexpr Spelling spellings[] = {{ParsedAttr::AS_GNU, "size"}, {ParsedAttr::AS_CXX11, "size"}, {ParsedAttr::AS_CXX11, "crossrt::size"}};
    Spellings = spellings;
    OptArgs = 15;
  }
  bool diagAppertainsToDecl(Sema& sema, const ParsedAttr& attr, const Decl* decl) const override {
    if (isa<ParmVarDecl>(decl)) return true;
    sema.Diag(attr.getLoc(), diag::warn_attribute_wrong_decl_type_str) << attr << attr.isRegularKeywordAttribute() << "parameters";
    return false;
  }
  AttrHandling handleDeclAttribute(Sema& sema, Decl* decl, const ParsedAttr& attr) const override {
    std::vector<std::string> factors;
    for (unsigned i = 0; i < attr.getNumArgs(); ++i) {
      auto* e = attr.isArgExpr(i) ? attr.getArgAsExpr(i) : nullptr;
      if (auto* str = e ? dyn_cast<StringLiteral>(e->IgnoreParenCasts()) : nullptr) factors.push_back(str->getString().str());
      else if (auto* number = e ? dyn_cast<IntegerLiteral>(e->IgnoreParenCasts()) : nullptr)
        factors.push_back(std::to_string(number->getValue().getZExtValue()));
    }
    if (factors.empty()) factors = ArgumentTexts(sema, attr);
    factors.erase(std::remove_if(factors.begin(), factors.end(), [](const std::string& f) {
                    return f.find_first_not_of(" \t") == std::string::npos;
                  }), factors.end());
    if (factors.empty()) {
      unsigned id = sema.getDiagnostics().getCustomDiagID(DiagnosticsEngine::Error,
          "size annotation needs the element count, e.g. [[crossrt::size(\"n\")]] or __attribute__((size(\"w\", \"h\")))");
      sema.Diag(attr.getLoc(), id);
      return AttributeNotApplied;
    }
    decl->addAttr(AnnotateAttr::Create(sema.Context, "crossrt.size=" + SizeProduct(factors), nullptr, 0, attr.getRange()));
    return AttributeApplied;
  }
};

}  // namespace

static ParsedAttrInfoRegistry::Add<SizeAttrInfo> registerSize("crossrt-size", "element count of a pointer parameter");

// Referenced by the translator so that the linker keeps this file's registration.
namespace crossrt::engine {
void LinkSizeAttribute() {}
}  // namespace crossrt::engine
