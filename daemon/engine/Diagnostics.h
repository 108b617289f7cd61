// Compiler-style diagnostics that point at the user's code: file:line:col: error: ... plus a hint note.
#pragma once
#include <clang/Basic/Diagnostic.h>
#include <clang/Basic/SourceLocation.h>
#include <clang/Basic/SourceManager.h>
#include <cstdint>
#include <set>
#include <string>
#include <utility>

namespace crossrt::engine {

class Reporter {
public:
  explicit Reporter(clang::DiagnosticsEngine& diags) : m_diags(diags) {}
  // Each error once: code several kernels share (a helper, a composed traversal) is checked for each.
  void Error(clang::SourceLocation loc, const std::string& message, const std::string& hint = {}) {
    ++m_errors;
    if (!m_reported.insert({loc.getRawEncoding(), message}).second) return;
    unsigned id = m_diags.getCustomDiagID(clang::DiagnosticsEngine::Error, "%0");
    m_diags.Report(loc, id) << message;
    if (!hint.empty()) {
      unsigned noteId = m_diags.getCustomDiagID(clang::DiagnosticsEngine::Note, "hint: %0");
      m_diags.Report(loc, noteId) << hint;
    }
    NoteWhereReached(loc);
  }
  // Translates, but the user should know: e.g. a control function the generated class cannot override.
  void Warning(clang::SourceLocation loc, const std::string& message, const std::string& hint = {}) {
    if (!m_reported.insert({loc.getRawEncoding(), message}).second) return;
    unsigned id = m_diags.getCustomDiagID(clang::DiagnosticsEngine::Warning, "%0");
    m_diags.Report(loc, id) << message;
    if (!hint.empty()) {
      unsigned noteId = m_diags.getCustomDiagID(clang::DiagnosticsEngine::Note, "hint: %0");
      m_diags.Report(loc, noteId) << hint;
    }
    NoteWhereReached(loc);
  }
  // A fact about the translation worth a line, e.g. a type that changes width on the GPU. (Clang
  // drops a note that follows no error or warning, so the reporter prints it itself: Notes().)
  void Note(clang::SourceLocation loc, const std::string& message) {
    if (!m_reported.insert({loc.getRawEncoding(), message}).second) return;
    m_notes += loc.printToString(m_diags.getSourceManager()) + ": note: " + message + "\n";
  }
  const std::string& Notes() const { return m_notes; }
  unsigned Errors() const { return m_errors; }

  // A rule of the GPU (what GLSL can express, buffer layouts, images, composition): an error when
  // translating for Vulkan, nothing for the CPU backend, whose classes run the user's C++ as written.
  void GpuError(clang::SourceLocation loc, const std::string& message, const std::string& hint = {}) {
    if (m_gpuRules) Error(loc, message, hint);
  }
  void SetGpuRules(bool on) { m_gpuRules = on; }
  bool GpuRules() const { return m_gpuRules; }
  // A rule of the Vulkan class's recording (a control function's body is recorded into a command
  // buffer before its kernels run: device copies of locals, what the host may do with data the GPU
  // holds meanwhile): an error for Vulkan only. The CPU and ISPC classes run control functions on
  // the host, in order, as written.
  void RecordingError(clang::SourceLocation loc, const std::string& message, const std::string& hint = {}) {
    if (m_recordingRules) Error(loc, message, hint);
  }
  void SetRecordingRules(bool on) { m_recordingRules = on; }
  bool RecordingRules() const { return m_recordingRules; }

  // While a pass analyses one kernel: an error or warning it finds outside the kernel's own body (in
  // a helper the kernel calls, a header's function) gets a note that points back at the kernel, the
  // other place involved (an editor shows it as related information).
  class ReachedFrom {
  public:
    ReachedFrom(Reporter& reporter, clang::SourceLocation at, const std::string& what, clang::SourceRange body)
        : m_reporter(reporter), m_saved(reporter.m_from) {
      reporter.m_from = {at, what, body};
    }
    ~ReachedFrom() { m_reporter.m_from = m_saved; }
    ReachedFrom(const ReachedFrom&) = delete;
    ReachedFrom& operator=(const ReachedFrom&) = delete;

  private:
    Reporter& m_reporter;
    struct Origin {
      clang::SourceLocation at;
      std::string what;
      clang::SourceRange body;
    } m_saved;
    friend class Reporter;
  };

private:
  void NoteWhereReached(clang::SourceLocation loc) {
    if (m_from.at.isInvalid() || loc.isInvalid()) return;
    const clang::SourceManager& sm = m_diags.getSourceManager();
    if (sm.isPointWithin(sm.getExpansionLoc(loc), sm.getExpansionLoc(m_from.body.getBegin()), sm.getExpansionLoc(m_from.body.getEnd())))
      return;
    unsigned id = m_diags.getCustomDiagID(clang::DiagnosticsEngine::Note, "reached from %0");
    m_diags.Report(m_from.at, id) << m_from.what;
  }

  clang::DiagnosticsEngine& m_diags;
  ReachedFrom::Origin m_from;
  unsigned m_errors = 0;
  bool m_gpuRules = true;
  bool m_recordingRules = true;
  std::string m_notes;
  std::set<std::pair<uint64_t, std::string>> m_reported;  // (location, message)
};

}  // namespace crossrt::engine
