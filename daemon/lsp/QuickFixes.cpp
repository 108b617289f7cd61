// Exact edits for diagnostics whose hint names one (QuickFixes.h).
#include "QuickFixes.h"

#include <algorithm>
#include <cctype>
#include <regex>

namespace crossrt::lsp {

namespace {

// [[crossrt::size("n")]] before a pointer parameter with none, its count the first integer parameter.
std::optional<TextEdit> SizeAttribute(const std::string& text, size_t nameAt) {
  // The declaration starts after the '(' or ',' before the name.
  size_t start = text.find_last_of("(,", nameAt);
  const size_t open = text.rfind('(', nameAt), close = text.find(')', nameAt);
  if (start == std::string::npos || open == std::string::npos || close == std::string::npos) return std::nullopt;
  ++start;
  while (start < nameAt && std::isspace((unsigned char)text[start])) ++start;
  if (text.substr(start, nameAt - start).find("size(") != std::string::npos) return std::nullopt;  // annotated already
  const std::string params = text.substr(open + 1, close - open - 1);
  static const std::regex integer(
      R"(\b(?:const\s+)?(?:int|unsigned(?:\s+int)?|uint|uint32_t|int32_t|size_t|uint64_t|int64_t)\s+([A-Za-z_]\w*)\s*(?:[,=]|$))");
  std::smatch m;
  const std::string count = std::regex_search(params, m, integer) ? m[1].str() : "n";
  const size_t lastNewline = start == 0 ? std::string::npos : text.rfind('\n', start - 1);
  const size_t lineStart = lastNewline == std::string::npos ? 0 : lastNewline + 1;
  const unsigned line = unsigned(std::count(text.begin(), text.begin() + long(start), '\n'));
  return TextEdit{line, unsigned(start - lineStart), "[[crossrt::size(\"" + count + "\")]] ",
                  "Add [[crossrt::size(\"" + count + "\")]] (its element count)"};
}

}  // namespace

std::optional<TextEdit> QuickFixFor(const std::string& message, const std::string& text, size_t at) {
  static const std::regex noSize(R"(pointer parameter '(\w+)' of control function '\w+' has no size)");
  std::smatch m;
  if (!std::regex_search(message, m, noSize)) return std::nullopt;
  if (at > text.size() || text.compare(at, m[1].length(), m[1].str()) != 0) return std::nullopt;  // the text moved on
  return SizeAttribute(text, at);
}

}  // namespace crossrt::lsp
