#include "InProcess.h"

#include "Protocol.h"

#include <climits>
#include <dlfcn.h>
#include <stdexcept>
#include <unistd.h>
#include <vector>

namespace crossrt::client {

namespace {

// libcrossrt-engine.so sits next to crossrt in the build tree, in ../lib/crossrt when installed.
std::vector<std::string> EngineCandidates() {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("CROSSRT_ENGINE")) candidates.push_back(env);
  char self[PATH_MAX];
  ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  if (n > 0) {
    self[n] = '\0';
    std::string dir(self);
    dir = dir.substr(0, dir.rfind('/'));
    candidates.push_back(dir + "/libcrossrt-engine.so");
    candidates.push_back(dir + "/../lib/crossrt/libcrossrt-engine.so");
  }
  return candidates;
}

void* LoadEngine() {
  std::string errors;
  for (auto& path : EngineCandidates()) {
    if (access(path.c_str(), R_OK) != 0) continue;
    if (void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) return handle;
    errors += std::string("\n  ") + dlerror();
  }
  throw std::runtime_error("cannot load the translation engine (libcrossrt-engine.so next to crossrt or in ../lib/crossrt)" + errors);
}

}  // namespace

std::string EnginePath() {
  for (auto& path : EngineCandidates())
    if (access(path.c_str(), R_OK) == 0) return path;
  return "";
}

engine::TranslateResult TranslateInProcess(const engine::TranslateRequest& request) {
  static void* engineModule = LoadEngine();
  using TranslateFn = char* (*)(const char*);
  using FreeFn = void (*)(char*);
  auto translate = reinterpret_cast<TranslateFn>(dlsym(engineModule, "crossrt_engine_translate"));
  auto release = reinterpret_cast<FreeFn>(dlsym(engineModule, "crossrt_engine_free"));
  if (!translate || !release) throw std::runtime_error("the translation engine module lacks its entry points");
  char* answer = translate(protocol::ToJson(request).dump().c_str());
  nlohmann::json response = nlohmann::json::parse(answer);
  release(answer);
  if (!response.value("ok", false)) throw std::runtime_error(response.value("error", "unknown error"));
  return protocol::ResultFromJson(response);
}

}  // namespace crossrt::client
