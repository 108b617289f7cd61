// What the crossrt client and the crossrtd daemon say to each other, and where they meet.
//
// One daemon serves one build tree. It listens on a Unix socket in a per-user directory that only
// its owner can enter (mode 0700, checked), named after a hash of the build tree's path; the
// socket itself is mode 0600 and the daemon refuses peers of another uid. A lock file next to the
// socket makes sure that one daemon at most runs per build tree, however many clients race to
// start one.
//
// Messages are single lines of JSON. Each connection carries one request and one response.
#pragma once
#include "TranslateTypes.h"

#include <nlohmann/json.hpp>

#include <string>

namespace crossrt::protocol {

constexpr int kProtocolVersion = 1;
constexpr size_t kMaxRequestBytes = 4u << 20;    // requests are small; anything larger is refused
constexpr size_t kMaxResponseBytes = 256u << 20;

struct Endpoint {
  std::string directory;  // per-user, mode 0700
  std::string socket;     // <directory>/<hash>.sock
  std::string lock;       // <directory>/<hash>.lock
};

// The endpoint of the daemon serving `buildDir`. Creates the per-user directory when missing and
// throws std::runtime_error when it exists but is not private to this user.
Endpoint EndpointFor(const std::string& buildDir);

// Which build of the translator an executable is: its version, size and modification time. A
// rebuilt translator is a different translator: its outputs may differ, so a daemon started
// before the rebuild must not answer, and translation keys change.
std::string TranslatorIdentity(const std::string& executable);

nlohmann::json ToJson(const engine::TranslateRequest& r);
engine::TranslateRequest RequestFromJson(const nlohmann::json& j);  // throws on missing fields

// The answer to a translate request: {"ok": true, "translated": ..., "diagnostics", "files", ...}.
nlohmann::json ResultToJson(const engine::TranslateResult& r);
engine::TranslateResult ResultFromJson(const nlohmann::json& j);   // throws on missing fields

// Blocking line IO on a socket. ReadLine returns false on EOF, error or a line over maxBytes
// (then `tooLong` is set).
bool WriteLine(int fd, const std::string& line);
bool ReadLine(int fd, std::string& line, size_t maxBytes, bool* tooLong = nullptr);

}  // namespace crossrt::protocol
