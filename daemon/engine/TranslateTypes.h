// What a translation takes and gives: plain data shared by the engine, the daemon, the protocol
// and the client (which does not link the engine).
#pragma once
#include <map>
#include <string>
#include <vector>

namespace crossrt::engine {

constexpr const char* kTranslatorVersion = "0.1.0";

enum class Backend { Vulkan, Cpu, Ispc };
// "vulkan", "cpu", "ispc"; and back (false for any other name).
inline const char* BackendName(Backend b) { return b == Backend::Vulkan ? "vulkan" : b == Backend::Cpu ? "cpu" : "ispc"; }
inline bool ParseBackend(const std::string& name, Backend& b) {
  for (Backend x : {Backend::Vulkan, Backend::Cpu, Backend::Ispc})
    if (name == BackendName(x)) { b = x; return true; }
  return false;
}

struct TranslateRequest {
  std::string className;                 // e.g. "MyRender"
  Backend backend = Backend::Vulkan;
  std::vector<std::string> sources;      // .cpp files that define the class's member functions
  std::vector<std::string> compileArgs;  // -I, -D, -std=... as the target compiles them
  std::string outputDir;                 // build-tree folder for the generated files
  std::string templateDir;               // templates/ (vulkan, glsl, cpu subfolders)
  // Composition (paper 3.6): "Interface=Implementation", e.g. "ISceneObject=BVHScene". Kernels that
  // call a member of type shared_ptr<Interface> get Implementation's code and data merged in; the
  // implementation's source files are among `sources`.
  std::vector<std::string> compositions;
  // Virtual functions (paper 3.9): 1 = every element in one array of equal slots, 2 = each class's
  // objects in a buffer of their own.
  int virtualLevel = 2;
  // Execution modes (paper 2.1 and 4.4) of thread loops that call several kernels: both are generated, this
  // is the one the generated class starts in.
  bool megakernel = false;
  // The generated class's name; empty: className + "_Vulkan", "_CPU" or "_ISPC". A given name also
  // prefixes the generated global symbols (SPIR-V arrays, ISPC kernels), so that several
  // translations of one class (at different virtual levels, say) link into one program.
  std::string generatedName;
  // In-process only (the language server; never sent to the daemon): editor buffers that stand for
  // files on disk, by absolute path. The sources and the headers they include are read from here
  // first, so that a translation sees what the user is typing before it is saved.
  std::map<std::string, std::string> unsavedFiles;
};

struct TranslateResult {
  bool ok = false;
  std::string diagnostics;                      // compiler-style text: file:line:col: error: ...
  std::map<std::string, std::string> files;     // file name (relative to outputDir) -> contents
  std::vector<std::string> inputs;              // every file the translation read (for depfiles)
  std::map<std::string, double> timingsMs;      // parse, analyze, generate, spirv
  // The sources did not parse: the diagnostics are the compiler's own, not the translator's (in-process only).
  bool parseFailed = false;
};

}  // namespace crossrt::engine
