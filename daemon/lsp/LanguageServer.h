// crossrtd --lsp: a Language Server Protocol server on stdin and stdout that runs beside clangd on
// the same files and tells the user, as they type, what the translator says of their class.
//
// It learns the classes from the build trees (BuildTree.h) and translates each class whose files
// an edit touches, for every backend the build asks for, from the editor's buffers (never writing
// into the build tree). It keeps its own ASTs warm, as the build's daemon does, in its own process:
// what an editor sends never reaches the build's daemon. It answers:
// - textDocument/publishDiagnostics after open, change (debounced) and save: each translation
//   error, warning and note at its place, its backends named, its hint in the message, the other
//   places involved as related information; cleared when fixed;
// - hover on the name of a kernel or control function (defined, declared or called): what it
//   becomes on each backend;
// - code lenses on them that open the generated code (crossrt.showGenerated), and
//   textDocument/definition from a generated line back to the user's function;
// - quick fixes where a hint names an exact edit (QuickFixes.h).
#pragma once
#include <string>
#include <vector>

namespace crossrt::lsp {

struct ServerOptions {
  std::vector<std::string> buildDirs;  // besides those the client names or the workspace holds
  int debounceMs = 50;                 // after a change, before translating
  std::string logPath;
};

// Serves one client on `in` and `out` until it says exit or goes away; returns the exit code.
int RunLanguageServer(const ServerOptions& options, int in, int out);

}  // namespace crossrt::lsp
