// The translator's diagnostics, read back from the compiler-style text it writes
// (file:line:col: error: message, then the source line and a caret, then its notes).
//
// A note that says "hint: ..." belongs to the error or warning before it, as its hint; other notes
// right after one are its related places; a note that follows no error stands alone (the
// translator's facts worth a line). A message without a place ("error: class 'X' is not defined")
// has an empty file.
#pragma once
#include <string>
#include <vector>

namespace crossrt::lsp {

struct TextPlace {
  std::string file;
  unsigned line = 0, column = 0;  // 1-based; 0 where the text gives none
};

struct CompilerDiagnostic {
  enum class Severity { Error = 1, Warning = 2, Note = 3 };
  Severity severity = Severity::Error;
  TextPlace at;
  std::string message;
  std::string hint;
  std::vector<std::pair<TextPlace, std::string>> related;
};

std::vector<CompilerDiagnostic> ParseCompilerText(const std::string& text);

}  // namespace crossrt::lsp
