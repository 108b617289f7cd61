// Reads compiler-style diagnostic text back into diagnostics (CompilerText.h).
#include "CompilerText.h"

#include <regex>
#include <sstream>

namespace crossrt::lsp {

std::vector<CompilerDiagnostic> ParseCompilerText(const std::string& text) {
  // "path:12:5: error: message", "path: error: message" (a file, no line) and "error: message".
  static const std::regex located(R"(^(.+?):(\d+):(\d+): (fatal error|error|warning|note): (.*)$)");
  static const std::regex fileOnly(R"(^([^ :][^:]*): (fatal error|error|warning|note): (.*)$)");
  static const std::regex bare(R"(^(fatal error|error|warning|note): (.*)$)");
  std::vector<CompilerDiagnostic> out;
  bool lastWasMain = false;  // the previous line of interest was an error or warning (notes attach to it)
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::smatch m;
    TextPlace at;
    std::string kind, message;
    if (std::regex_match(line, m, located)) {
      at = {m[1].str(), unsigned(std::stoul(m[2].str())), unsigned(std::stoul(m[3].str()))};
      kind = m[4].str();
      message = m[5].str();
    } else if (std::regex_match(line, m, bare)) {
      kind = m[1].str();
      message = m[2].str();
    } else if (std::regex_match(line, m, fileOnly)) {
      at.file = m[1].str();
      kind = m[2].str();
      message = m[3].str();
    } else {
      continue;  // the source line and caret under a diagnostic, "In file included from ..."
    }
    if (kind == "note") {
      if (lastWasMain && !out.empty()) {
        if (message.rfind("hint: ", 0) == 0 && out.back().hint.empty()) out.back().hint = message.substr(6);
        else out.back().related.push_back({at, message});
        continue;
      }
      CompilerDiagnostic note;
      note.severity = CompilerDiagnostic::Severity::Note;
      note.at = at;
      note.message = message;
      out.push_back(note);
      lastWasMain = false;
      continue;
    }
    CompilerDiagnostic d;
    d.severity = kind == "warning" ? CompilerDiagnostic::Severity::Warning : CompilerDiagnostic::Severity::Error;
    d.at = at;
    d.message = message;
    out.push_back(d);
    lastWasMain = true;
  }
  return out;
}

}  // namespace crossrt::lsp
