// The translation engine: turns one user class into generated source files.
// It knows nothing about sockets or processes: the daemon hosts it, and the client loads it
// (EnginePlugin.cpp) to translate in-process when no daemon can answer.
#pragma once
#include "parse/Arguments.h"
#include "Model.h"
#include "compile/Spirv.h"
#include "TranslateTypes.h"

#include <map>
#include <string>
#include <vector>

namespace crossrt::engine {

struct AnalyzeResult {
  bool ok = false;
  bool parseFailed = false;  // the diagnostics are the compiler's
  std::string diagnostics;
  ClassModel model;
  std::vector<std::string> inputs;
  std::map<std::string, double> timingsMs;
};

class AstCache;

// Parses and analyses only: what the translator finds in the class. With a cache, parsed files
// are kept and reparsed (the daemon); without, they are parsed and dropped.
AnalyzeResult Analyze(const TranslateRequest& request, AstCache* cache = nullptr);

// Parses, analyses and generates. Does not write anything. With `model`, the analysis's model is
// copied there when the analysis succeeded (the language server describes kernels from it).
TranslateResult Translate(const TranslateRequest& request, AstCache* cache = nullptr, SpirvCache* spirvCache = nullptr,
                          ClassModel* model = nullptr);

inline const char* TranslatorVersion() { return kTranslatorVersion; }

}  // namespace crossrt::engine
