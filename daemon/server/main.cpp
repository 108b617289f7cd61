// crossrtd: the translation daemon. One per build tree; the crossrt client starts it on demand.
// It keeps parsed ASTs (with precompiled preambles) in memory so that re-translating an edited
// class costs a reparse of the edited file, not a parse of the standard library.
//
//   crossrtd --build-dir DIR [--log FILE] [--idle-seconds N] [--max-asts N]
//   crossrtd --lsp [--build-dir DIR...] [--log FILE] [--debounce-ms N]
//
// With --lsp it is instead a language server for an editor, on stdin and stdout (../lsp).
//
// It exits after N idle seconds (default 900), on `crossrt daemon stop`, or when a client of
// another version asks (so that the client can start its own).
//
// Test hook: CROSSRT_DAEMON_CRASH_AT=<stage> makes it SIGKILL itself at that stage of a
// translate request (accepted, read, parsed, translated, responding), or hang with "hang", to
// test client recovery.
#include "CommandLine.h"
#include "parse/AstCache.h"
#include "LanguageServer.h"
#include "Protocol.h"
#include "Translator.h"

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fcntl.h>
#include <fstream>
#include <iostream>
#include <mutex>
#include <poll.h>
#include <string>
#include <sys/file.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/un.h>
#include <thread>
#include <unistd.h>

using nlohmann::json;
namespace engine = crossrt::engine;
namespace protocol = crossrt::protocol;

namespace {

struct Daemon {
  std::string buildDir, logPath;
  int idleSeconds = 900;
  size_t maxAsts = 16;
  std::unique_ptr<engine::AstCache> cache;
  engine::SpirvCache spirv;
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  std::atomic<long> lastActivity{0};  // seconds since start
  std::atomic<int> active{0};
  std::atomic<bool> stopping{false};
  std::atomic<uint64_t> requests{0}, translations{0}, failures{0};
  std::mutex logMutex;
  std::ofstream log;
  std::string crashAt;
  std::string socketPath;
  std::string identity = protocol::TranslatorIdentity("/proc/self/exe");  // this build, as started

  // Stop taking requests at once: new clients find no socket and start a fresh daemon.
  void Stop() {
    if (!stopping.exchange(true)) unlink(socketPath.c_str());
  }

  long Now() const {
    return long(std::chrono::duration_cast<std::chrono::seconds>(std::chrono::steady_clock::now() - started).count());
  }
  void Log(const std::string& message) {
    std::lock_guard<std::mutex> guard(logMutex);
    if (!log.is_open()) return;
    std::time_t t = std::time(nullptr);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M:%S", std::localtime(&t));
    log << stamp << " [" << getpid() << "] " << message << std::endl;
  }
  void MaybeCrash(const char* stage) {
    if (crashAt == "hang" && std::string(stage) == "parsed") {
      Log("test hook: hanging");
      std::this_thread::sleep_for(std::chrono::hours(1));
    }
    if (crashAt == stage) {
      Log(std::string("test hook: SIGKILL at stage '") + stage + "'");
      raise(SIGKILL);
    }
  }
};

size_t ResidentBytes() {
  std::ifstream statm("/proc/self/statm");
  size_t pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * size_t(sysconf(_SC_PAGESIZE));
}

json Status(Daemon& d) {
  auto stats = d.cache->Stats();
  uint64_t lookups = stats.parses + stats.reparses;
  return {{"pid", getpid()},
          {"version", engine::TranslatorVersion()},
          {"engine", d.identity},
          {"protocol", protocol::kProtocolVersion},
          {"buildDir", d.buildDir},
          {"uptimeSeconds", d.Now()},
          {"idleTimeoutSeconds", d.idleSeconds},
          {"cachedAsts", stats.entries},
          {"maxCachedAsts", stats.capacity},
          {"residentBytes", ResidentBytes()},
          {"requestsServed", d.requests.load()},
          {"translations", d.translations.load()},
          {"failedTranslations", d.failures.load()},
          {"parses", stats.parses},
          {"cachedShaders", d.spirv.Size()},
          {"reparses", stats.reparses},
          {"reuses", stats.reuses},
          {"systemLayers", stats.layers},
          {"layeredPreambles", stats.layeredPreambles},
          {"astHitRate", lookups ? double(stats.reparses) / double(lookups) : 0.0}};
}

json Handle(Daemon& d, const std::string& line) {
  json request;
  try {
    request = json::parse(line);
  } catch (const std::exception& e) {
    return {{"ok", false}, {"error", std::string("malformed request: not JSON (") + e.what() + ")"}};
  }
  if (!request.is_object() || !request.contains("protocol") || !request["protocol"].is_number_integer())
    return {{"ok", false}, {"error", "malformed request: no protocol version"}};
  bool otherBuild = request.contains("engine") && request["engine"] != d.identity;
  if (request["protocol"].get<int>() != protocol::kProtocolVersion || request.value("version", "") != engine::TranslatorVersion() ||
      otherBuild) {
    // The client runs another version, or the translator was rebuilt since this daemon started:
    // step aside so that the client can start a daemon of its own build.
    d.Stop();
    return {{"ok", false}, {"error", "version-mismatch"}, {"daemonVersion", engine::TranslatorVersion()},
            {"daemonProtocol", protocol::kProtocolVersion}};
  }
  std::string command = request.value("command", "");
  if (command == "status") return {{"ok", true}, {"status", Status(d)}};
  if (command == "stop") {
    d.Stop();
    return {{"ok", true}};
  }
  if (command != "translate") return {{"ok", false}, {"error", "malformed request: unknown command '" + command + "'"}};

  engine::TranslateRequest tr;
  try {
    tr = protocol::RequestFromJson(request.at("request"));
  } catch (const std::exception& e) {
    return {{"ok", false}, {"error", std::string("malformed request: ") + e.what()}};
  }
  d.MaybeCrash("parsed");
  auto t0 = std::chrono::steady_clock::now();
  engine::TranslateResult result = engine::Translate(tr, d.cache.get(), &d.spirv);
  double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ++d.translations;
  if (!result.ok) ++d.failures;
  std::string phases;
  for (auto& [phase, t] : result.timingsMs) phases += " " + phase + " " + std::to_string(int(t));
  d.Log("translate " + tr.className + " (" + engine::BackendName(tr.backend) + "): " +
        (result.ok ? "ok" : "failed") + " in " + std::to_string(int(ms)) + " ms (" + phases.substr(phases.empty() ? 0 : 1) + ")");
  d.MaybeCrash("translated");
  return protocol::ResultToJson(result);
}

void Serve(Daemon& d, int fd) {
  d.MaybeCrash("accepted");
  // Only this user's processes may talk to the daemon.
  struct ucred peer {};
  socklen_t len = sizeof peer;
  if (getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &peer, &len) != 0 || peer.uid != getuid()) {
    protocol::WriteLine(fd, json{{"ok", false}, {"error", "refused: the daemon serves its owner only"}}.dump());
    d.Log("refused a connection from uid " + std::to_string(peer.uid));
    close(fd);
    return;
  }
  std::string line;
  bool tooLong = false;
  json response;
  if (!protocol::ReadLine(fd, line, protocol::kMaxRequestBytes, &tooLong)) {
    if (tooLong) {
      response = {{"ok", false}, {"error", "request too large (over " + std::to_string(protocol::kMaxRequestBytes) + " bytes)"}};
      d.Log("refused an oversized request");
    } else {
      close(fd);  // the client went away
      return;
    }
  } else {
    d.MaybeCrash("read");
    try {
      response = Handle(d, line);
    } catch (const std::exception& e) {
      response = {{"ok", false}, {"error", std::string("internal error: ") + e.what()}};
      d.Log(std::string("internal error: ") + e.what());
    }
  }
  ++d.requests;
  d.MaybeCrash("responding");
  protocol::WriteLine(fd, response.dump(-1, ' ', false, json::error_handler_t::replace));
  close(fd);
}

}  // namespace

// crossrtd --lsp: the language server (LanguageServer.h) on stdin and stdout.
int LanguageServerMain(const crossrt::lsp::ServerOptions& options) {
  signal(SIGPIPE, SIG_IGN);  // a client gone: writes fail, and the server exits
  return crossrt::lsp::RunLanguageServer(options, STDIN_FILENO, STDOUT_FILENO);
}

int main(int argc, char** argv) {
  Daemon d;
  crossrt::lsp::ServerOptions lsp;
  std::vector<std::string> buildDirs;
  std::string logPath;
  bool languageServer = false;
  crossrt::CommandLine app("crossrtd",
                           "The translation daemon of one build tree: keeps parsed ASTs warm and answers the crossrt client.\n"
                           "crossrt starts it on demand; you rarely run it by hand.\n"
                           "With --lsp, a language server for editors (beside clangd) on stdin and stdout: the translator's\n"
                           "diagnostics while you type, hovers and code lenses on kernels, quick fixes. It learns the classes\n"
                           "from the build trees (--build-dir, the client's initializationOptions.buildDirectory, or the\n"
                           "workspace folder and its subfolders holding CMakeCache.txt). docs/editors.md sets it up.");
  app.add_option("--build-dir", buildDirs, "the build tree it serves (with --lsp: build trees to learn classes from, any number)");
  app.add_option("--log", logPath, "a log of what it does");
  CLI::Option* idle = app.add_option("--idle-seconds", d.idleSeconds, "exits after this long without a request")->check(crossrt::Positive());
  CLI::Option* asts = app.add_option("--max-asts", d.maxAsts, "parsed translation units kept warm")->check(crossrt::Positive());
  CLI::Option* serveLsp = app.add_flag("--lsp", languageServer, "serve the Language Server Protocol on stdin and stdout instead");
  app.add_option("--debounce-ms", lsp.debounceMs, "with --lsp: after a change, wait this long before translating")
      ->check(CLI::Range(0, 10000))
      ->needs(serveLsp);
  serveLsp->excludes(idle)->excludes(asts);
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  if (languageServer) {
    lsp.buildDirs = buildDirs;
    lsp.logPath = logPath;
    return LanguageServerMain(lsp);
  }
  if (buildDirs.size() != 1) {
    std::cerr << "crossrtd: give one --build-dir, the build tree to serve (see --help)\n";
    return 2;
  }
  d.buildDir = buildDirs.front();
  d.logPath = logPath;
  if (const char* crash = std::getenv("CROSSRT_DAEMON_CRASH_AT")) d.crashAt = crash;
  signal(SIGPIPE, SIG_IGN);

  protocol::Endpoint ep;
  try {
    ep = protocol::EndpointFor(d.buildDir);
  } catch (const std::exception& e) {
    std::cerr << "crossrtd: " << e.what() << "\n";
    return 1;
  }
  // At most one daemon per build tree: whoever holds the lock serves.
  int lockFd = open(ep.lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (lockFd < 0 || flock(lockFd, LOCK_EX | LOCK_NB) != 0) {
    std::cerr << "crossrtd: a daemon already serves " << d.buildDir << "\n";
    return 0;
  }
  if (!d.logPath.empty()) d.log.open(d.logPath, std::ios::app);

  unlink(ep.socket.c_str());  // a socket left by a killed daemon
  int server = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (ep.socket.size() >= sizeof addr.sun_path) {
    std::cerr << "crossrtd: socket path too long: " << ep.socket << "\n";
    return 1;
  }
  std::strncpy(addr.sun_path, ep.socket.c_str(), sizeof addr.sun_path - 1);
  mode_t old = umask(077);
  int bound = bind(server, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  umask(old);
  if (bound != 0 || chmod(ep.socket.c_str(), 0600) != 0 || listen(server, 64) != 0) {
    std::cerr << "crossrtd: cannot listen on " << ep.socket << ": " << std::strerror(errno) << "\n";
    return 1;
  }
  d.cache = std::make_unique<engine::AstCache>(d.maxAsts, engine::AstCache::LayerPreparation::AfterReparse);
  d.Log("serving " + d.buildDir + " on " + ep.socket + " (idle timeout " + std::to_string(d.idleSeconds) +
        " s, at most " + std::to_string(d.maxAsts) + " cached ASTs)");

  d.socketPath = ep.socket;
  while (!d.stopping) {
    pollfd pfd{server, POLLIN, 0};
    int ready = poll(&pfd, 1, 1000);
    if (d.stopping) break;  // a stopping daemon takes no new requests
    if (ready > 0) {
      int fd = accept4(server, nullptr, nullptr, SOCK_CLOEXEC);
      if (fd < 0) continue;
      if (d.active >= 64) {  // bounded: the client translates in-process instead
        protocol::WriteLine(fd, json{{"ok", false}, {"error", "busy: 64 requests in progress"}}.dump());
        close(fd);
        continue;
      }
      timeval tv{30, 0};  // a client that connects and says nothing must not pin the daemon
      setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
      d.lastActivity = d.Now();
      ++d.active;
      std::thread([&d, fd] {
        Serve(d, fd);
        d.lastActivity = d.Now();
        --d.active;
      }).detach();
    } else if (d.active == 0 && d.Now() - d.lastActivity > d.idleSeconds) {
      d.Log("idle for " + std::to_string(d.idleSeconds) + " s: exiting");
      break;
    }
  }
  // Stop taking connections, let running requests answer, then go.
  if (!d.stopping) unlink(ep.socket.c_str());
  close(server);
  for (int i = 0; i < 600 && d.active > 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  d.Log("stopped");
  std::_Exit(0);  // requests still running after a minute are abandoned, not raced by destructors
}
