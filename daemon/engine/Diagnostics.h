// Compiler-style diagnostics that point at the user's code: file:line:col: error: ... plus a hint note.
#pragma once
#include <clang/Basic/Diagnostic.h>
#include <clang/Basic/SourceLocation.h>
#include <string>

namespace crossrt::engine {

class Reporter {
public:
  explicit Reporter(clang::DiagnosticsEngine& diags) : m_diags(diags) {}
  void Error(clang::SourceLocation loc, const std::string& message, const std::string& hint = {}) {
    unsigned id = m_diags.getCustomDiagID(clang::DiagnosticsEngine::Error, "%0");
    m_diags.Report(loc, id) << message;
    if (!hint.empty()) {
      unsigned noteId = m_diags.getCustomDiagID(clang::DiagnosticsEngine::Note, "hint: %0");
      m_diags.Report(loc, noteId) << hint;
    }
    ++m_errors;
  }
  unsigned Errors() const { return m_errors; }

private:
  clang::DiagnosticsEngine& m_diags;
  unsigned m_errors = 0;
};

}  // namespace crossrt::engine
