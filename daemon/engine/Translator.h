// The translation engine: turns one user class into generated source files.
// It knows nothing about sockets or processes: the client runs it in-process, the daemon will host it.
#pragma once
#include "Model.h"

#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace crossrt::engine {

enum class Backend { Vulkan, Cpu };

struct TranslateRequest {
  std::string className;                 // e.g. "MyRender"
  Backend backend = Backend::Vulkan;
  std::vector<std::string> sources;      // .cpp files that define the class's member functions
  std::vector<std::string> compileArgs;  // -I, -D, -std=... as the target compiles them
  std::string outputDir;                 // build-tree folder for the generated files
  std::string templateDir;               // templates/ (vulkan, glsl, cpu subfolders)
  std::string glslangValidator = "glslangValidator";  // compiles generated GLSL to SPIR-V
};

struct TranslateResult {
  bool ok = false;
  std::string diagnostics;                      // compiler-style text: file:line:col: error: ...
  std::map<std::string, std::string> files;     // file name (relative to outputDir) -> contents
  std::vector<std::string> inputs;              // every file the translation read (for depfiles)
  std::map<std::string, double> timingsMs;      // parse, analyze, generate, spirv
};

struct AnalyzeResult {
  bool ok = false;
  std::string diagnostics;
  ClassModel model;
  std::vector<std::string> inputs;
  std::map<std::string, double> timingsMs;
};

class AstCache;

// SPIR-V of GLSL sources already compiled, by content: an edit recompiles only the shaders whose
// text changed. The daemon keeps one for its lifetime.
class SpirvCache {
public:
  bool Find(const std::string& glsl, std::vector<uint32_t>& words) const;
  void Add(const std::string& glsl, const std::vector<uint32_t>& words);
  size_t Size() const;

private:
  mutable std::mutex m_mutex;
  std::map<std::string, std::vector<uint32_t>> m_byGlsl;
};

// Parses and analyses only: what the translator finds in the class. With a cache, parsed files
// are kept and reparsed (the daemon); without, they are parsed and dropped.
AnalyzeResult Analyze(const TranslateRequest& request, AstCache* cache = nullptr);

// Parses, analyses and generates. Does not write anything.
TranslateResult Translate(const TranslateRequest& request, AstCache* cache = nullptr, SpirvCache* spirvCache = nullptr);

// The compile arguments the engine parses with: the request's, plus what the engine adds.
std::vector<std::string> ParseArguments(const TranslateRequest& request);

// Writes result.files into outputDir atomically, touching only files whose bytes changed.
// Returns the names of the files it rewrote. Throws std::runtime_error on IO failure.
std::vector<std::string> WriteOutputs(const TranslateRequest& request, const TranslateResult& result);

const char* TranslatorVersion();

}  // namespace crossrt::engine
