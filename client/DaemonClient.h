// Talking to crossrtd: connect, start it when absent, send one request, read one response.
// Every failure comes back as a message, never an exception: the caller falls back to translating
// in-process, so a missing, crashed or hung daemon never fails the build.
#pragma once
#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace crossrt::client {

class DaemonClient {
public:
  explicit DaemonClient(std::string buildDir) : m_buildDir(std::move(buildDir)) {}

  // Sends `request` (protocol and version are added) and returns the response, starting the
  // daemon first when `start` and none answers. nullopt with Error() set when that failed.
  std::optional<nlohmann::json> Call(nlohmann::json request, bool start, int timeoutSeconds = 600);
  const std::string& Error() const { return m_error; }

private:
  int Connect();
  bool Start();
  std::string m_buildDir, m_error;
};

}  // namespace crossrt::client
