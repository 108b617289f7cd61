// The translation key of a generated folder. A translation is a pure function of its inputs (the
// class's sources and every header they include, the templates), its options and the translator's
// version; the manifest records their hashes, so an unchanged key is recognised without parsing.
#pragma once
#include "TranslateTypes.h"

#include <string>
#include <vector>

namespace crossrt::client {

struct Manifest {
  std::string optionsKey;                                   // hash of version + request options
  std::vector<std::pair<std::string, std::string>> inputs;  // path, content hash
  std::vector<std::string> outputs;                         // file names in the output folder
};

std::string OptionsKey(const engine::TranslateRequest& request);
std::string HashFile(const std::string& path);  // "" when unreadable
std::string ManifestPath(const engine::TranslateRequest& request);

// True when a manifest exists for these options, every input still has its recorded hash and
// every output exists: the translation would write exactly what is there.
bool UpToDate(const engine::TranslateRequest& request);
void WriteManifest(const engine::TranslateRequest& request, const engine::TranslateResult& result);

// The request itself, as the daemon receives it, in <buildDir>/.crossrt/requests/: the language
// server (crossrtd --lsp) learns the build tree's classes from these. Written on every translation,
// failed ones too (the class the user is fixing), only when its bytes change, and never into the
// output folder (a failed translation writes nothing there).
std::string RequestPath(const engine::TranslateRequest& request, const std::string& buildDir);
void RecordRequest(const engine::TranslateRequest& request, const std::string& buildDir);

}  // namespace crossrt::client
