// What the language server reads in a translation's generated files, and where it keeps them.
//
// The generator marks each piece it writes with where it came from ("// from Bloom::kernel2D_BlurX
// (Bloom.cpp)", "// ---- Run (from Bloom::Run, Bloom.cpp) ----"). From those marks the server finds
// a kernel's code in each file, and the user's function from any generated line. A shader's own
// declarations say what a kernel becomes on the GPU: its workgroup size and its bindings.
//
// The generated files of an editor's translation are written under the user's cache folder
// ($XDG_CACHE_HOME/crossrt/lsp, else ~/.cache/crossrt/lsp), never into the build tree: builds stay
// the build's job.
#pragma once
#include <map>
#include <string>
#include <vector>

namespace crossrt::lsp {

// A private folder for one translation's generated files (`key`: its output folder).
std::string GeneratedFolder(const std::string& key);

// Writes `files` (name relative to `folder` -> text) where their bytes changed.
void WriteGenerated(const std::string& folder, const std::map<std::string, std::string>& files);

// The 1-based line of `text` that marks the code generated from `qualifiedName` (Bloom::kernel2D_BlurX):
// the last such mark, the one above the code; 0 for none.
unsigned LineGeneratedFrom(const std::string& text, const std::string& qualifiedName);

// The function a generated line came from: the nearest mark at or above 1-based `line`, or "".
std::string FunctionAtLine(const std::string& text, unsigned line);

struct ShaderBinding {
  unsigned binding = 0;
  std::string name;    // the buffer's array: m_weights, src
  std::string access;  // "read-only", "write-only" or "read-write"
  std::string what;    // the generator's comment: "member std::vector m_weights", "parameter 'src'"
};

struct ShaderFacts {
  unsigned group[3] = {0, 0, 0};  // local_size_x, _y, _z; 0 where the text has none
  std::vector<ShaderBinding> buffers;
};

ShaderFacts ReadShader(const std::string& glsl);

}  // namespace crossrt::lsp
