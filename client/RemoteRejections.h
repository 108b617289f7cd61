// The remote cache entries a build tree refused to use because they did not verify against the
// team key (TeamKey.h): each is a line in <build>/.crossrt-remote-rejections, appended by the
// translation that met it, and `crossrt daemon status` prints their count and the last one. A file
// and not the daemon's memory, because the remote cache is read by `crossrt translate` before any
// daemon is asked, and the record must outlive a daemon that exits when idle.
#pragma once
#include <string>

namespace crossrt::client {

// Appends one rejection (a no-op without a build tree).
void RecordRejection(const std::string& buildDir, const std::string& storage, const std::string& what,
                     const std::string& reason);

struct Rejections {
  size_t count = 0;
  std::string last;  // "<UTC time> <storage>: <what>: <reason>", "" when none
};
Rejections ReadRejections(const std::string& buildDir);

}  // namespace crossrt::client
