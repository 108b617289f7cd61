// Quick fixes for the diagnostics whose hint names an exact edit.
//
// Today one: "pointer parameter 'in' of control function 'Run' has no size" gets
// [[crossrt::size("n")]] before the parameter's declaration, where n is the function's first
// integer parameter (else "n", for the user to rename).
#pragma once
#include <optional>
#include <string>

namespace crossrt::lsp {

struct TextEdit {
  unsigned line = 0, column = 0;  // 0-based, in bytes of the line
  std::string insert;
  std::string title;
};

// The fix for `message` reported at byte offset `at` of `text`, if it has one.
std::optional<TextEdit> QuickFixFor(const std::string& message, const std::string& text, size_t at);

}  // namespace crossrt::lsp
