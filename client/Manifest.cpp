#include "Manifest.h"

#include "DaemonClient.h"
#include "InProcess.h"
#include "Protocol.h"

#include <nlohmann/json.hpp>
#include <xxhash.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace crossrt::client {

namespace {
std::string Hex(uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}
}  // namespace

std::string OptionsKey(const engine::TranslateRequest& r) {
  // The translator's build is part of the key: a rebuilt translator translates again, the daemon's
  // and the engine module's that --no-daemon loads (a target may be rebuilt alone).
  std::string text = protocol::TranslatorIdentity(DaemonExecutable()) + '\n' + protocol::TranslatorIdentity(EnginePath()) + '\n' + r.className + '\n' +
                     engine::BackendName(r.backend) + '\n' + r.templateDir;
  for (auto& s : r.sources) text += "\nsrc " + s;
  for (auto& a : r.compileArgs) text += "\narg " + a;
  for (auto& c : r.compositions) text += "\ncompose " + c;
  text += "\nvirtual-level " + std::to_string(r.virtualLevel);
  text += std::string("\nexecution-mode ") + (r.megakernel ? "megakernel" : "wavefront");
  text += "\nname " + r.generatedName;
  return Hex(XXH64(text.data(), text.size(), 0));
}

std::string HashFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::ostringstream os;
  os << in.rdbuf();
  std::string data = os.str();
  return Hex(XXH64(data.data(), data.size(), 0));
}

std::string ManifestPath(const engine::TranslateRequest& r) { return r.outputDir + "/.crossrt-manifest.json"; }

bool UpToDate(const engine::TranslateRequest& request) {
  std::ifstream in(ManifestPath(request));
  if (!in) return false;
  nlohmann::json m;
  try {
    in >> m;
    if (m.at("optionsKey").get<std::string>() != OptionsKey(request)) return false;
    for (auto& out : m.at("outputs"))
      if (!std::filesystem::exists(request.outputDir + "/" + out.get<std::string>())) return false;
    for (auto& input : m.at("inputs"))
      if (HashFile(input.at(0).get<std::string>()) != input.at(1).get<std::string>()) return false;
  } catch (const std::exception&) {
    return false;  // unreadable: translate again
  }
  return true;
}

void WriteManifest(const engine::TranslateRequest& request, const engine::TranslateResult& result) {
  nlohmann::json m;
  m["optionsKey"] = OptionsKey(request);
  m["inputs"] = nlohmann::json::array();
  for (auto& in : result.inputs) m["inputs"].push_back({in, HashFile(in)});
  m["outputs"] = nlohmann::json::array();
  for (auto& [name, contents] : result.files) m["outputs"].push_back(name);
  std::string path = ManifestPath(request), tmp = path + ".tmp";
  std::ofstream(tmp) << m.dump(1) << "\n";
  std::filesystem::rename(tmp, path);
}

std::string RequestPath(const engine::TranslateRequest& r, const std::string& buildDir) {
  return buildDir + "/.crossrt/requests/" + Hex(XXH64(r.outputDir.data(), r.outputDir.size(), 0)) + ".json";
}

void RecordRequest(const engine::TranslateRequest& request, const std::string& buildDir) {
  if (buildDir.empty()) return;  // by hand, outside a build tree: no editor to tell
  const std::string text = protocol::ToJson(request).dump(1) + "\n", path = RequestPath(request, buildDir);
  std::ifstream old(path);
  std::string previous((std::istreambuf_iterator<char>(old)), std::istreambuf_iterator<char>());
  if (previous == text) return;
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
  const std::string tmp = path + ".tmp";
  std::ofstream(tmp) << text;
  std::filesystem::rename(tmp, path, ec);  // best effort: a build never fails for the editor's sake
}

}  // namespace crossrt::client
