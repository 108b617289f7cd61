// The translation daemon, as builds meet it: real crossrt and crossrtd processes, each test with a
// build tree of its own (so its own daemon), stopped at the end.
#include "EngineSupport.h"
#include "Protocol.h"

#include <algorithm>
#include <csignal>
#include <dirent.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <thread>

namespace {

const char* kHeader = R"(#pragma once
#include "LiteMath.h"
class Scale
{
public:
  virtual ~Scale() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* data);
protected:
  void kernel1D_Scale(int n, float* data);
  float m_factor = 2.0f;
};
)";

const char* kSource = R"(#include "Scale.h"
void Scale::Run(int n, float* data) { kernel1D_Scale(n, data); }
void Scale::kernel1D_Scale(int n, float* data)
{
  for (int i = 0; i < n; i++)
    data[i] = data[i] * m_factor + 1.0f;
}
)";

std::string ReadText(const fs::path& p)
{
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// A class, a build tree and the commands a build runs for it.
struct DaemonFixture
{
  TempClass tc{"Scale", kHeader, kSource};
  fs::path build = tc.dir / "build";
  fs::path out = build / "gen";
  DaemonFixture()
  {
    fs::create_directories(build);
    setenv("CROSSRT_DAEMON_IDLE_SECONDS", "60", 1);
    unsetenv("CROSSRT_DAEMON_CRASH_AT");
    unsetenv("CROSSRT_NO_DAEMON");
  }
  ~DaemonFixture()
  {
    RunCrossrt("daemon stop --build-dir " + build.string());
    unsetenv("CROSSRT_DAEMON_CRASH_AT");
  }
  std::string TranslateArgs(const fs::path& outDir, bool daemon = true) const
  {
    return "translate --class Scale --backend vulkan --out " + outDir.string() + " --source " + tc.Source("Scale") +
           " --templates " CROSSRT_SOURCE_DIR "/templates" +
           (daemon ? " --build-dir " + build.string() : std::string(" --no-daemon")) + " -- -I" CROSSRT_SOURCE_DIR "/libs/litemath";
  }
  CommandResult Translate(const fs::path& outDir) const { return RunCrossrt(TranslateArgs(outDir)); }
  nlohmann::json Status() const
  {
    auto r = RunCrossrt("daemon status --json --build-dir " + build.string());
    return nlohmann::json::parse(r.output);
  }
  // The generated files of a folder, without the manifest.
  std::map<std::string, std::string> Generated(const fs::path& dir) const
  {
    std::map<std::string, std::string> files;
    for (auto& e : fs::recursive_directory_iterator(dir))
      if (e.is_regular_file() && e.path().filename() != ".crossrt-manifest.json")
        files[fs::relative(e.path(), dir).string()] = ReadText(e.path());
    return files;
  }
};

// Sends raw bytes to the daemon and returns its answer (one line).
std::string RawRequest(const fs::path& build, const std::string& bytes)
{
  auto ep = crossrt::protocol::EndpointFor(build.string());
  int fd = socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, ep.socket.c_str(), sizeof addr.sun_path - 1);
  REQUIRE(connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0);
  size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = send(fd, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n <= 0) break;  // the daemon may stop reading an oversized request
    done += size_t(n);
  }
  shutdown(fd, SHUT_WR);
  std::string line;
  crossrt::protocol::ReadLine(fd, line, 1 << 20);
  close(fd);
  return line;
}

// Daemon processes serving a build tree, found through /proc.
int DaemonsServing(const fs::path& build)
{
  int count = 0;
  for (auto& e : fs::directory_iterator("/proc")) {
    std::string cmdline = ReadText(e.path() / "cmdline");
    std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
    if (cmdline.find("crossrtd") != std::string::npos && cmdline.find("--build-dir " + build.string() + " ") != std::string::npos) ++count;
  }
  return count;
}

}  // namespace

TEST_CASE("The daemon translates, caches ASTs, and reports its status", "[daemon]")
{
  DaemonFixture f;
  auto first = f.Translate(f.out);
  INFO(first.output);
  REQUIRE(first.exitCode == 0);
  REQUIRE(first.output.find("in-process") == std::string::npos);  // the daemon answered
  auto s = f.Status();
  REQUIRE(s["running"] == true);
  REQUIRE(s["translations"] == 1);
  REQUIRE(s["cachedAsts"] == 1);
  REQUIRE(s["residentBytes"].get<size_t>() > 0);
  REQUIRE(s.contains("astHitRate"));

  // The same output as an in-process translation.
  fs::path reference = f.build / "reference";
  REQUIRE(RunCrossrt(f.TranslateArgs(reference, false)).exitCode == 0);
  REQUIRE(f.Generated(f.out) == f.Generated(reference));

  // An edit reparses the cached AST (preamble reused) instead of parsing anew.
  std::ofstream(f.tc.Source("Scale"), std::ios::app) << "// a trailing comment\n";
  REQUIRE(f.Translate(f.out).exitCode == 0);
  s = f.Status();
  REQUIRE(s["reparses"] == 1);
  REQUIRE(s["parses"] == 1);

  // Human-readable status too.
  auto text = RunCrossrt("daemon status --build-dir " + f.build.string());
  REQUIRE(text.output.find("cached ASTs") != std::string::npos);
  REQUIRE(text.output.find("AST hit rate") != std::string::npos);
}

TEST_CASE("Unchanged inputs write nothing, and comment or whitespace edits leave outputs byte-identical", "[daemon]")
{
  DaemonFixture f;
  REQUIRE(f.Translate(f.out).exitCode == 0);
  auto before = f.Generated(f.out);
  std::map<std::string, fs::file_time_type> stamps;
  for (auto& [name, text] : before) stamps[name] = fs::last_write_time(f.out / name);

  // No change at all.
  REQUIRE(f.Translate(f.out).exitCode == 0);
  REQUIRE(f.Status()["translations"] == 1);  // answered from the manifest: the daemon was not asked

  // Comments and whitespace inside a kernel and a control function.
  std::string src = ReadText(f.tc.Source("Scale"));
  std::string edited = src;
  edited.replace(edited.find("kernel1D_Scale(n, data); }"), 26, "kernel1D_Scale(n,   data);  /* why */ }");
  edited.replace(edited.find("data[i] * m_factor"), 18, "data[i]*m_factor  // scaled\n      ");
  std::ofstream(f.tc.Source("Scale")) << edited;
  REQUIRE(f.Translate(f.out).exitCode == 0);
  REQUIRE(f.Status()["translations"] == 2);  // it did translate
  REQUIRE(f.Generated(f.out) == before);
  for (auto& [name, stamp] : stamps) REQUIRE(fs::last_write_time(f.out / name) == stamp);  // nothing rewritten

  // A real kernel edit changes exactly what it should.
  std::ofstream(f.tc.Source("Scale")) << std::string(src).replace(src.find("+ 1.0f"), 6, "+ 3.0f");
  REQUIRE(f.Translate(f.out).exitCode == 0);
  auto after = f.Generated(f.out);
  REQUIRE(after["shaders/kernel1D_Scale.comp"].find("+ 3.0") != std::string::npos);
  REQUIRE(after["shaders/kernel1D_Scale.comp"] != before["shaders/kernel1D_Scale.comp"]);
  REQUIRE(after["Scale_Vulkan.h"] == before["Scale_Vulkan.h"]);
}

TEST_CASE("A rebuilt engine module translates again without the daemon", "[daemon]")
{
  // The engine --no-daemon loads, a copy of the build's, rebuilt (here: touched) alone, as
  // `ninja bin/libcrossrt-engine.so` does: the class is translated again, not answered from the manifest.
  DaemonFixture f;
  const fs::path engine = f.tc.dir / "libcrossrt-engine.so";
  fs::copy_file(fs::path(CROSSRT_CLIENT).parent_path() / "libcrossrt-engine.so", engine);
  setenv("CROSSRT_ENGINE", engine.c_str(), 1);
  auto key = [&] { return nlohmann::json::parse(ReadText(f.out / ".crossrt-manifest.json"))["optionsKey"].get<std::string>(); };
  REQUIRE(RunCrossrt(f.TranslateArgs(f.out, false)).exitCode == 0);
  const std::string first = key();
  REQUIRE(RunCrossrt(f.TranslateArgs(f.out, false)).exitCode == 0);
  CHECK(key() == first);  // nothing changed
  fs::last_write_time(engine, fs::last_write_time(engine) + std::chrono::seconds(2));
  auto r = RunCrossrt(f.TranslateArgs(f.out, false));
  unsetenv("CROSSRT_ENGINE");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  CHECK(key() != first);
  CHECK(ReadText(f.out / "shaders/kernel1D_Scale.comp").find("m_factor") != std::string::npos);
}

TEST_CASE("A SIGKILL of the daemon at any stage of a request still gives the right output", "[daemon]")
{
  for (const char* stage : {"accepted", "read", "parsed", "translated", "responding"}) {
    SECTION(stage)
    {
      DaemonFixture f;
      fs::path reference = f.build / "reference";
      REQUIRE(RunCrossrt(f.TranslateArgs(reference, false)).exitCode == 0);
      setenv("CROSSRT_DAEMON_CRASH_AT", stage, 1);
      auto r = f.Translate(f.out);
      INFO(r.output);
      REQUIRE(r.exitCode == 0);
      REQUIRE(r.output.find("translating in-process") != std::string::npos);
      REQUIRE(f.Generated(f.out) == f.Generated(reference));
      // The next request starts a healthy daemon over the stale socket.
      unsetenv("CROSSRT_DAEMON_CRASH_AT");
      std::ofstream(f.tc.Source("Scale"), std::ios::app) << "\n";
      r = f.Translate(f.out);
      REQUIRE(r.exitCode == 0);
      REQUIRE(r.output.find("in-process") == std::string::npos);
      REQUIRE(DaemonsServing(f.build) == 1);
    }
  }
}

TEST_CASE("A hung daemon does not hang the build", "[daemon]")
{
  DaemonFixture f;
  fs::path reference = f.build / "reference";
  REQUIRE(RunCrossrt(f.TranslateArgs(reference, false)).exitCode == 0);
  setenv("CROSSRT_DAEMON_CRASH_AT", "hang", 1);
  setenv("CROSSRT_DAEMON_TIMEOUT_SECONDS", "2", 1);
  auto r = f.Translate(f.out);
  unsetenv("CROSSRT_DAEMON_TIMEOUT_SECONDS");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  REQUIRE(r.output.find("translating in-process") != std::string::npos);
  REQUIRE(f.Generated(f.out) == f.Generated(reference));
  // The hung daemon is still there: stop it by its pid (the fixture's stop request would wait).
  for (auto& e : fs::directory_iterator("/proc")) {
    std::string cmdline = ReadText(e.path() / "cmdline");
    std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
    if (cmdline.find("crossrtd") != std::string::npos && cmdline.find(f.build.string() + " ") != std::string::npos)
      kill(std::stoi(e.path().filename().string()), SIGKILL);
  }
}

TEST_CASE("Clients racing to start the daemon end with exactly one", "[daemon]")
{
  DaemonFixture f;
  std::vector<std::thread> clients;
  std::vector<CommandResult> results(6);
  for (int i = 0; i < 6; ++i)
    clients.emplace_back([&, i] { results[i] = RunCrossrt(f.TranslateArgs(f.build / ("out" + std::to_string(i)))); });
  for (auto& t : clients) t.join();
  for (auto& r : results) {
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
  }
  REQUIRE(DaemonsServing(f.build) == 1);
}

TEST_CASE("Malformed, oversized and foreign requests get an error while the daemon keeps serving", "[daemon]")
{
  DaemonFixture f;
  REQUIRE(f.Translate(f.out).exitCode == 0);  // starts the daemon
  const std::string version = crossrt::engine::TranslatorVersion();
  auto expectError = [&](const std::string& bytes, const std::string& what) {
    auto answer = nlohmann::json::parse(RawRequest(f.build, bytes));
    INFO(answer.dump());
    REQUIRE(answer["ok"] == false);
    REQUIRE(answer["error"].get<std::string>().find(what) != std::string::npos);
  };
  expectError("this is not json\n", "not JSON");
  expectError("[1, 2, 3]\n", "no protocol version");
  expectError(R"({"protocol": 1, "version": ")" + version + R"(", "command": "dance"})" "\n", "unknown command");
  expectError(R"({"protocol": 1, "version": ")" + version + R"(", "command": "translate", "request": {"className": "X"}})" "\n", "malformed request");
  expectError(R"({"protocol": 1, "version": ")" + version + R"(", "command": "translate", "request": {"className": "X", "backend": "metal", "sources": ["a"], "compileArgs": [], "outputDir": "o", "templateDir": "t"}})" "\n", "unknown backend");
  expectError(std::string(crossrt::protocol::kMaxRequestBytes + 10, 'x') + "\n", "request too large");
  // Still serving.
  auto s = f.Status();
  REQUIRE(s["running"] == true);
  REQUIRE(s["requestsServed"].get<int>() >= 7);
}

TEST_CASE("A client of another version makes the daemon restart", "[daemon]")
{
  DaemonFixture f;
  REQUIRE(f.Translate(f.out).exitCode == 0);
  int oldPid = f.Status()["pid"];
  auto answer = nlohmann::json::parse(RawRequest(f.build, R"({"protocol": 1, "version": "0.0.1-other", "command": "status"})" "\n"));
  REQUIRE(answer["error"] == "version-mismatch");
  std::ofstream(f.tc.Source("Scale"), std::ios::app) << "\n";
  auto r = f.Translate(f.out);  // starts a daemon of its own version
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  REQUIRE(f.Status()["pid"] != oldPid);
}

TEST_CASE("Sockets are private to their owner", "[daemon]")
{
  DaemonFixture f;
  REQUIRE(f.Translate(f.out).exitCode == 0);
  auto ep = crossrt::protocol::EndpointFor(f.build.string());
  struct stat st {};
  REQUIRE(stat(ep.socket.c_str(), &st) == 0);
  REQUIRE((st.st_mode & 0777) == 0600);
  REQUIRE(stat(ep.directory.c_str(), &st) == 0);
  REQUIRE((st.st_mode & 0777) == 0700);
}

TEST_CASE("Errors through the daemon: an unwritable output folder, a source that does not parse", "[daemon]")
{
  DaemonFixture f;
  REQUIRE(f.Translate(f.out).exitCode == 0);
  if (getuid() != 0) {  // root writes anywhere: only a non-root user can test the unwritable folder
    fs::path locked = f.build / "locked";
    fs::create_directories(locked);
    fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
    auto r = f.Translate(locked / "gen");
    REQUIRE(r.exitCode == 1);
    REQUIRE(r.output.find("cannot create directory") != std::string::npos);
    fs::permissions(locked, fs::perms::owner_all);
  } else {
    // As root: an output path that runs through a regular file cannot be created either.
    std::ofstream(f.build / "afile") << "x";
    auto r = f.Translate(f.build / "afile" / "gen");
    INFO(r.output);
    REQUIRE(r.exitCode == 1);
    REQUIRE(r.output.find("cannot create directory") != std::string::npos);
  }
  std::ofstream(f.tc.Source("Scale"), std::ios::app) << "void Broken() { int x = ; }\n";
  auto r = f.Translate(f.out);
  INFO(r.output);
  REQUIRE(r.exitCode == 1);
  REQUIRE(r.output.find("Scale.cpp:8:25: error: expected expression") != std::string::npos);
  REQUIRE(r.output.find("in-process") == std::string::npos);  // the daemon answered it
  REQUIRE(f.Status()["running"] == true);
}
