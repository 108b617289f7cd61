// The translation engine: turns one user class into generated source files.
// It knows nothing about sockets or processes: the daemon hosts it, and the client loads it
// (EnginePlugin.cpp) to translate in-process when no daemon can answer.
#pragma once
#include "Model.h"
#include "TranslateTypes.h"

#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace crossrt::engine {

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

inline const char* TranslatorVersion() { return kTranslatorVersion; }

}  // namespace crossrt::engine
