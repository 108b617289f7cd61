// The record of rejected remote cache entries (RemoteRejections.h).
#include "RemoteRejections.h"

#include <fcntl.h>
#include <unistd.h>

#include <ctime>
#include <fstream>

namespace crossrt::client {

namespace {
std::string LogPath(const std::string& buildDir) { return buildDir + "/.crossrt-remote-rejections"; }
}  // namespace

void RecordRejection(const std::string& buildDir, const std::string& storage, const std::string& what,
                     const std::string& reason) {
  if (buildDir.empty()) return;
  char when[32];
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", gmtime_r(&now, &utc));
  std::string line = std::string(when) + " " + storage + ": " + what + ": " + reason;
  for (char& c : line)
    if (c == '\n' || c == '\r') c = ' ';
  line += "\n";
  // One write with O_APPEND: the lines of parallel translations never interleave.
  const int fd = open(LogPath(buildDir).c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) return;
  [[maybe_unused]] const ssize_t written = write(fd, line.data(), line.size());
  close(fd);
}

Rejections ReadRejections(const std::string& buildDir) {
  Rejections r;
  std::ifstream in(LogPath(buildDir));
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) ++r.count, r.last = line;
  return r;
}

}  // namespace crossrt::client
