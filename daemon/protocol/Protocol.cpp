#include "Protocol.h"

#include <xxhash.h>

#include <cerrno>
#include <cstring>
#include <climits>
#include <cstdlib>
#include <stdexcept>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

namespace crossrt::protocol {

Endpoint EndpointFor(const std::string& buildDir) {
  char resolved[PATH_MAX];
  std::string tree = realpath(buildDir.c_str(), resolved) ? resolved : buildDir;
  const char* runtime = std::getenv("XDG_RUNTIME_DIR");
  std::string dir = (runtime && *runtime && access(runtime, W_OK) == 0) ? std::string(runtime) + "/crossrt"
                                                                         : "/tmp/crossrt-" + std::to_string(getuid());
  if (mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST)
    throw std::runtime_error("cannot create the daemon directory '" + dir + "'");
  struct stat st {};
  if (lstat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != getuid() || (st.st_mode & 077) != 0)
    throw std::runtime_error("the daemon directory '" + dir + "' is not a private directory of this user (mode 0700)");
  char name[32];
  std::snprintf(name, sizeof name, "%016llx", static_cast<unsigned long long>(XXH64(tree.data(), tree.size(), 0)));
  return {dir, dir + "/" + name + ".sock", dir + "/" + name + ".lock"};
}

std::string TranslatorIdentity(const std::string& executable) {
  struct stat st {};
  if (stat(executable.c_str(), &st) != 0) return std::string(engine::kTranslatorVersion) + "/unknown";
  char buf[96];
  std::snprintf(buf, sizeof buf, "%s/%llx-%llx.%09ld-%llx", engine::kTranslatorVersion, (unsigned long long)st.st_size,
                (unsigned long long)st.st_mtim.tv_sec, (long)st.st_mtim.tv_nsec, (unsigned long long)st.st_ino);
  return buf;
}

nlohmann::json ToJson(const engine::TranslateRequest& r) {
  return {{"className", r.className},
          {"backend", engine::BackendName(r.backend)},
          {"sources", r.sources},
          {"compileArgs", r.compileArgs},
          {"outputDir", r.outputDir},
          {"templateDir", r.templateDir},
          {"compositions", r.compositions},
          {"virtualLevel", r.virtualLevel},
          {"executionMode", r.megakernel ? "megakernel" : "wavefront"},
          {"generatedName", r.generatedName}};
}

engine::TranslateRequest RequestFromJson(const nlohmann::json& j) {
  engine::TranslateRequest r;
  r.className = j.at("className").get<std::string>();
  std::string backend = j.at("backend").get<std::string>();
  if (!engine::ParseBackend(backend, r.backend)) throw std::runtime_error("unknown backend '" + backend + "'");
  r.sources = j.at("sources").get<std::vector<std::string>>();
  r.compileArgs = j.at("compileArgs").get<std::vector<std::string>>();
  r.outputDir = j.at("outputDir").get<std::string>();
  r.templateDir = j.at("templateDir").get<std::string>();
  if (j.contains("compositions")) r.compositions = j.at("compositions").get<std::vector<std::string>>();
  if (j.contains("virtualLevel")) r.virtualLevel = j.at("virtualLevel").get<int>();
  if (r.virtualLevel < 1 || r.virtualLevel > 3) throw std::runtime_error("virtualLevel must be 1, 2 or 3");
  if (j.contains("executionMode")) {
    std::string mode = j.at("executionMode").get<std::string>();
    if (mode != "megakernel" && mode != "wavefront") throw std::runtime_error("executionMode must be megakernel or wavefront, not '" + mode + "'");
    r.megakernel = mode == "megakernel";
  }
  if (j.contains("generatedName")) r.generatedName = j.at("generatedName").get<std::string>();
  if (r.className.empty() || r.sources.empty()) throw std::runtime_error("className and sources must not be empty");
  return r;
}

nlohmann::json ResultToJson(const engine::TranslateResult& r) {
  return {{"ok", true},       {"translated", r.ok}, {"diagnostics", r.diagnostics},
          {"files", r.files}, {"inputs", r.inputs}, {"timingsMs", r.timingsMs}};
}

engine::TranslateResult ResultFromJson(const nlohmann::json& j) {
  engine::TranslateResult r;
  r.ok = j.at("translated").get<bool>();
  r.diagnostics = j.at("diagnostics").get<std::string>();
  r.files = j.at("files").get<std::map<std::string, std::string>>();
  r.inputs = j.at("inputs").get<std::vector<std::string>>();
  if (j.contains("timingsMs")) r.timingsMs = j["timingsMs"].get<std::map<std::string, double>>();
  return r;
}

bool WriteLine(int fd, const std::string& line) {
  std::string data = line + "\n";
  size_t done = 0;
  while (done < data.size()) {
    ssize_t n = ::send(fd, data.data() + done, data.size() - done, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}

bool ReadLine(int fd, std::string& line, size_t maxBytes, bool* tooLong) {
  line.clear();
  if (tooLong) *tooLong = false;
  char buf[65536];
  while (true) {
    ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    const char* end = static_cast<const char*>(memchr(buf, '\n', size_t(n)));
    line.append(buf, end ? size_t(end - buf) : size_t(n));
    if (line.size() > maxBytes) {
      if (tooLong) *tooLong = true;
      return false;
    }
    if (end) return true;  // one request per connection: nothing follows the newline
  }
}

}  // namespace crossrt::protocol
