// Talking to crossrtd: connect, start it when absent, send one request, read one response.
// Every failure comes back as a message, never an exception: the caller falls back to translating
// in-process, so a missing, crashed or hung daemon never fails the build.
#pragma once
#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace crossrt::client {

// The crossrtd executable next to crossrt (or CROSSRT_DAEMON).
std::string DaemonExecutable();

class DaemonClient {
public:
  explicit DaemonClient(std::string buildDir) : m_buildDir(std::move(buildDir)) {}

  // Sends `request` (protocol and version are added) and returns the response, starting the
  // daemon first when `start` and none answers. nullopt with Error() set when that failed.
  // A daemon that has not answered after `timeoutSeconds` is taken as hung (default: 120 s, or
  // CROSSRT_DAEMON_TIMEOUT_SECONDS); the caller then translates in-process.
  std::optional<nlohmann::json> Call(nlohmann::json request, bool start, int timeoutSeconds = 0);
  const std::string& Error() const { return m_error; }

private:
  int Connect();
  bool Start();
  std::string m_buildDir, m_error;
};

}  // namespace crossrt::client
