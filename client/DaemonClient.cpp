#include "DaemonClient.h"

#include "Protocol.h"
#include "TranslateTypes.h"

#include <chrono>
#include <climits>
#include <cstring>
#include <fcntl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace crossrt::client {

// crossrtd lives next to crossrt (bin/ of the build tree or of the installation).
std::string DaemonExecutable() {
  if (const char* env = std::getenv("CROSSRT_DAEMON")) return env;
  char self[PATH_MAX];
  ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  if (n <= 0) return "crossrtd";
  self[n] = '\0';
  std::string dir(self);
  return dir.substr(0, dir.rfind('/')) + "/crossrtd";
}

int DaemonClient::Connect() {
  protocol::Endpoint ep;
  try {
    ep = protocol::EndpointFor(m_buildDir);
  } catch (const std::exception& e) {
    m_error = e.what();
    return -1;
  }
  int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, ep.socket.c_str(), sizeof addr.sun_path - 1);
  if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    m_error = "cannot connect to " + ep.socket + ": " + std::strerror(errno);
    close(fd);
    return -1;
  }
  return fd;
}

// Starts crossrtd detached from the build (double fork, new session, no inherited stdio).
bool DaemonClient::Start() {
  std::string exe = DaemonExecutable();
  if (access(exe.c_str(), X_OK) != 0) {
    m_error = "the daemon executable '" + exe + "' is missing";
    return false;
  }
  std::string log = m_buildDir + "/crossrtd.log";
  pid_t child = fork();
  if (child < 0) return false;
  if (child == 0) {
    setsid();
    if (fork() != 0) _exit(0);
    // The daemon keeps nothing of the build: no inherited descriptors (a make jobserver's pipes
    // would keep the build waiting), no working directory.
    int devnull = open("/dev/null", O_RDWR);
    dup2(devnull, 0);
    dup2(devnull, 1);
    dup2(devnull, 2);
    for (int fd = 3; fd < 1024; ++fd) close(fd);
    if (chdir("/") != 0) _exit(126);
    // CROSSRT_DAEMON_IDLE_SECONDS shortens the idle timeout (tests use it).
    const char* idle = std::getenv("CROSSRT_DAEMON_IDLE_SECONDS");
    if (idle)
      execl(exe.c_str(), exe.c_str(), "--build-dir", m_buildDir.c_str(), "--log", log.c_str(), "--idle-seconds", idle, (char*)nullptr);
    else
      execl(exe.c_str(), exe.c_str(), "--build-dir", m_buildDir.c_str(), "--log", log.c_str(), (char*)nullptr);
    _exit(127);
  }
  waitpid(child, nullptr, 0);
  return true;
}

std::optional<nlohmann::json> DaemonClient::Call(nlohmann::json request, bool start, int timeoutSeconds) {
  request["protocol"] = protocol::kProtocolVersion;
  request["version"] = engine::kTranslatorVersion;
  request["engine"] = protocol::TranslatorIdentity(DaemonExecutable());
  for (int attempt = 0; attempt < 2; ++attempt) {
    int fd = Connect();
    if (fd < 0 && start) {
      // Absent, or a stale socket of a killed daemon: start one and wait for it to listen. When
      // two clients race, the daemons' lock lets one serve; both clients connect to it.
      if (!Start()) return std::nullopt;
      for (int i = 1; i <= 100 && fd < 0; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        fd = Connect();
        // A daemon that was stopping still held the lock, and ours stepped aside: try again.
        if (fd < 0 && i % 20 == 0) Start();
      }
    }
    if (fd < 0) return std::nullopt;
    if (timeoutSeconds <= 0) {
      const char* env = std::getenv("CROSSRT_DAEMON_TIMEOUT_SECONDS");
      timeoutSeconds = env && std::atoi(env) > 0 ? std::atoi(env) : 120;
    }
    timeval tv{timeoutSeconds, 0};  // a hung daemon must not hang the build
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    std::string line;
    bool sent = protocol::WriteLine(fd, request.dump());
    bool got = sent && protocol::ReadLine(fd, line, protocol::kMaxResponseBytes);
    close(fd);
    if (!got) {
      m_error = "the daemon closed the connection before answering (crashed or timed out)";
      return std::nullopt;
    }
    nlohmann::json response;
    try {
      response = nlohmann::json::parse(line);
    } catch (const std::exception& e) {
      m_error = std::string("unreadable answer from the daemon: ") + e.what();
      return std::nullopt;
    }
    if (response.value("error", "") == "version-mismatch" && start && attempt == 0) {
      // It is stepping down; give it a moment to release its lock, then start ours.
      std::this_thread::sleep_for(std::chrono::milliseconds(1200));
      continue;
    }
    return response;
  }
  m_error = "the daemon runs another version and did not make way";
  return std::nullopt;
}

}  // namespace crossrt::client
