// crossrt: the command crossrt_add_class() runs.
//
//   crossrt translate --class NAME --backend vulkan|cpu|ispc --out DIR --source FILE... [options] [-- ARGS]
//   crossrt daemon status [--build-dir DIR] [--json]      (with the remote cache's rejected entries)
//   crossrt daemon stop [--build-dir DIR]
//   crossrt --help | --version
//
// translate: when the recorded translation key is unchanged it writes nothing and returns at
// once. Otherwise it looks in the remote storages (CROSSRT_REMOTE_STORAGE), then asks the build
// tree's daemon (starting it when absent) and, when the daemon cannot answer for any reason,
// translates in-process: the build never fails because of the daemon or a remote storage. A local
// translation is uploaded. Outputs are written atomically, only where their bytes changed.
#include "CommandLine.h"
#include "DaemonClient.h"
#include "InProcess.h"
#include "Manifest.h"
#include "Outputs.h"
#include "Protocol.h"
#include "RemoteCache.h"
#include "RemoteRejections.h"
#include "SourceFinder.h"
#include "TranslateTypes.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>
#include <vector>

namespace engine = crossrt::engine;
using crossrt::client::DaemonClient;

namespace {

const char* kDescription =
    "crossrt: translates a C++ class into a class that runs its kernels on Vulkan (NAME_Vulkan), on\n"
    "all CPU cores (NAME_CPU), or on all cores in SIMD lanes (NAME_ISPC, whose NAME_ISPC_kernels.ispc\n"
    "the ISPC compiler compiles). crossrt_add_class() in CMake runs it; you rarely call it by hand.\n"
    "crossrt COMMAND --help describes a command.";
const char* kTranslate =
    "translates class NAME, whose member functions the --source files define, into DIR. Of the --candidate\n"
    "files (a target's sources), those that define NAME's member functions are parsed too, whatever their\n"
    "names. Compile arguments (-I, -D, -std=...) follow '--'. The build tree's daemon (crossrtd) translates,\n"
    "and is started when absent; --no-daemon (or CROSSRT_NO_DAEMON=1) translates in this process. An\n"
    "unchanged class writes nothing.\n"
    "--remote-storage (or CROSSRT_REMOTE_STORAGE, which wins) names remote caches shared by a team:\n"
    "redis://host[:port], http[s]://host/path, space-separated, each with optional |read-only,\n"
    "|connect-timeout=MS, |operation-timeout=MS, |layout=bazel, |ca-file=PEM (trusts that certificate\n"
    "authority for https:// storages). Paths under --build-dir and --source-root are stored relative to\n"
    "them. With a team key (CROSSRT_REMOTE_KEY, or the file that CROSSRT_REMOTE_KEY_FILE or\n"
    "--remote-key-file names; never the key itself on a command line) entries are signed, and entries\n"
    "that do not verify are rejected: translated locally instead.";

// Relative paths in the request, made absolute from this process's folder: the daemon that
// translates runs elsewhere.
void MakePathsAbsolute(engine::TranslateRequest& request) {
  auto absolute = [](std::string& path) {
    if (!path.empty() && path[0] != '/') path = (std::filesystem::current_path() / path).lexically_normal().string();
  };
  for (auto& s : request.sources) absolute(s);
  absolute(request.outputDir);
  absolute(request.templateDir);
  auto& args = request.compileArgs;
  for (size_t i = 0; i < args.size(); ++i) {
    for (const char* flag : {"-I", "-isystem", "-iquote", "-idirafter", "-include"}) {
      const std::string f = flag;
      if (args[i] == f && i + 1 < args.size()) {
        absolute(args[++i]);
        break;
      }
      if (args[i].size() > f.size() && args[i].compare(0, f.size(), f) == 0 && (f == "-I" || args[i][f.size()] != '-')) {
        std::string path = args[i].substr(f.size());
        absolute(path);
        args[i] = f + path;
        break;
      }
    }
  }
}

int Usage(const std::string& message) {
  std::cerr << "crossrt: error: " << message << " (see --help)\n";
  return 2;
}

// Make-style depfile: "target: input1 input2 ..." with spaces escaped.
bool WriteDepfile(const std::string& path, const std::string& target, const std::vector<std::string>& inputs) {
  auto escape = [](const std::string& s) {
    std::string out;
    for (char c : s) {
      if (c == ' ' || c == '#') out += '\\';
      if (c == '$') out += '$';
      out += c;
    }
    return out;
  };
  std::string text = escape(target) + ":";
  for (auto& in : inputs) text += " \\\n  " + escape(in);
  text += "\n";
  std::ifstream old(path);
  std::string previous((std::istreambuf_iterator<char>(old)), std::istreambuf_iterator<char>());
  if (previous == text) return true;
  std::ofstream out(path, std::ios::trunc);
  out << text;
  return out.good();
}

std::string CurrentDir() {
  char buf[4096];
  return getcwd(buf, sizeof buf) ? buf : ".";
}

// crossrt daemon status|stop.
int DaemonCommand(const std::string& what, const std::string& buildDir, bool asJson) {
  DaemonClient daemon(buildDir);
  auto response = daemon.Call({{"command", what}}, /*start=*/false, 10);
  // Rejected remote entries are the build tree's record, not the daemon's: shown with or without one.
  const crossrt::client::Rejections rejections = crossrt::client::ReadRejections(buildDir);
  const nlohmann::json rejectionsJson{{"count", rejections.count}, {"last", rejections.last}};
  auto printRejections = [&] {
    std::printf("  remote cache    %zu %s rejected%s%s\n", rejections.count, rejections.count == 1 ? "entry" : "entries",
                rejections.count ? "; the last: " : "", rejections.last.c_str());
  };
  if (!response) {
    if (asJson) std::cout << nlohmann::json{{"running", false}, {"buildDir", buildDir}, {"remoteRejections", rejectionsJson}}.dump(2) << "\n";
    else {
      std::cout << "no daemon serves " << buildDir << "\n";
      if (what == "status" && rejections.count) printRejections();
    }
    return what == "stop" ? 0 : 1;
  }
  if (!response->value("ok", false)) {
    std::cerr << "crossrt: daemon: " << response->value("error", "unknown error") << "\n";
    return 1;
  }
  if (what == "stop") {
    // Return once it has exited: its lock on the build tree is free again.
    std::string lock = crossrt::protocol::EndpointFor(buildDir).lock;
    for (int i = 0; i < 300; ++i) {
      int fd = open(lock.c_str(), O_RDWR | O_CLOEXEC);
      bool free = fd >= 0 && flock(fd, LOCK_EX | LOCK_NB) == 0;
      if (fd >= 0) close(fd);
      if (free) break;
      usleep(50 * 1000);
    }
    std::cout << "stopped the daemon of " << buildDir << "\n";
    return 0;
  }
  const auto& s = (*response)["status"];
  if (asJson) {
    nlohmann::json out = s;
    out["running"] = true;
    out["remoteRejections"] = rejectionsJson;
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  std::printf("crossrtd %s serving %s\n", s.value("version", "?").c_str(), s.value("buildDir", "?").c_str());
  std::printf("  pid             %d\n", s.value("pid", 0));
  std::printf("  uptime          %ld s (exits after %d s idle)\n", s.value("uptimeSeconds", 0L), s.value("idleTimeoutSeconds", 0));
  std::printf("  cached ASTs     %zu of %zu\n", s.value("cachedAsts", size_t(0)), s.value("maxCachedAsts", size_t(0)));
  std::printf("  memory          %.1f MiB resident\n", double(s.value("residentBytes", size_t(0))) / (1024.0 * 1024.0));
  std::printf("  requests served %llu (%llu translations, %llu failed)\n", (unsigned long long)s.value("requestsServed", 0ull),
              (unsigned long long)s.value("translations", 0ull), (unsigned long long)s.value("failedTranslations", 0ull));
  std::printf("  AST hit rate    %.0f%% (%llu reparses, %llu of them ASTs used as they were, %llu parses)\n",
              100.0 * s.value("astHitRate", 0.0), (unsigned long long)s.value("reparses", 0ull),
              (unsigned long long)s.value("reuses", 0ull), (unsigned long long)s.value("parses", 0ull));
  std::printf("  preambles       %llu built over a layer of system headers (%llu layers built)\n",
              (unsigned long long)s.value("layeredPreambles", 0ull), (unsigned long long)s.value("systemLayers", 0ull));
  printRejections();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // The team key never on a command line, where other users and build logs see it: refused before
  // anything reads it.
  for (int i = 1; i < argc; ++i)
    if (std::string a = argv[i]; a == "--remote-key" || a.rfind("--remote-key=", 0) == 0)
      return Usage("the team key is never given on the command line, where other users and build logs see it: "
                   "set CROSSRT_REMOTE_KEY, or name a key file with --remote-key-file or CROSSRT_REMOTE_KEY_FILE");
  engine::TranslateRequest request;
  request.templateDir = CROSSRT_DEFAULT_TEMPLATE_DIR;
  std::string depfile, depfileTarget, backend, buildDir, sourceDir, remoteStorage, sourceRoot, remoteKeyFile;
  std::string virtualLevel, executionMode, daemonDir = CurrentDir();
  bool noDaemon = false, asJson = false, version = false;
  std::vector<std::string> candidates;

  crossrt::CommandLine app("crossrt", kDescription);
  app.add_flag("--version", version, "prints the translator's version");
  app.require_subcommand(0, 1);
  // `crossrt help`, as before CLI11: the same as --help (hidden from the list of commands).
  CLI::App* help = app.add_subcommand("help", "")->group("")->allow_extras();
  CLI::App* translate = app.add_subcommand("translate", kTranslate);
  auto one = [](CLI::Option* o) { return o->allow_extra_args(false); };  // one value per occurrence
  translate->add_option("--class", request.className, "the class, NAME")->required();
  translate->add_option("--backend", backend, "vulkan, cpu or ispc")->required();
  translate->add_option("--out", request.outputDir, "the folder of the generated files, DIR")->required();
  one(translate->add_option("--source", request.sources, "a file that defines NAME's member functions"));
  one(translate->add_option("--candidate", candidates, "a file of the target, parsed when it defines NAME's member functions"));
  translate->add_option("--source-dir", sourceDir, "where relative --candidate files are");
  one(translate->add_option("--compose", request.compositions, "INTERFACE=IMPLEMENTATION: the implementation the GPU runs (paper 3.6)"));
  translate->add_option("--virtual-level", virtualLevel,
                        "1 (one array of equal slots), 2 (a buffer per class) or 3 (2, plus callable and intersection shaders)");
  translate->add_option("--execution-mode", executionMode,
                        "megakernel (one shader per thread loop) or wavefront (one dispatch per kernel call)");
  translate->add_option("--name", request.generatedName,
                        "the generated class's name (and its files' and global symbols') instead of NAME_Vulkan, NAME_CPU or\n"
                        "NAME_ISPC, so that several translations of one class link into one program");
  translate->add_option("--templates", request.templateDir, "the templates' folder");
  translate->add_option("--depfile", depfile, "a make-style depfile of the translation's inputs");
  translate->add_option("--depfile-target", depfileTarget, "the depfile's target");
  translate->add_option("--build-dir", buildDir, "the build tree, whose daemon translates");
  translate->add_flag("--no-daemon", noDaemon, "translates in this process");
  translate->add_option("--remote-storage", remoteStorage, "remote caches shared by a team (see above)");
  translate->add_option("--source-root", sourceRoot, "paths under it are stored relative to it in remote caches");
  translate->add_option("--remote-key-file", remoteKeyFile, "the file that holds the team key");
  translate->add_option("COMPILE_ARGS", request.compileArgs, "compile arguments, after '--'");
  CLI::App* daemon = app.add_subcommand("daemon", "the build tree's daemon (crossrtd)");
  daemon->require_subcommand(1);
  CLI::App* status = daemon->add_subcommand("status", "prints what the build tree's daemon holds, and how many remote cache entries the build tree rejected");
  status->add_option("--build-dir", daemonDir, "the build tree");
  status->add_flag("--json", asJson, "for a machine");
  CLI::App* stop = daemon->add_subcommand("stop", "stops it; the next translation starts another");
  stop->add_option("--build-dir", daemonDir, "the build tree");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;

  if (help->parsed()) {  // crossrt's own help (app.help() would describe the help command)
    std::fputs(app.get_formatter()->make_help(&app, app.get_name(), CLI::AppFormatMode::Normal).c_str(), stdout);
    return 0;
  }
  if (version) {
    std::cout << "crossrt " << engine::kTranslatorVersion << "\n";
    return 0;
  }
  if (daemon->parsed()) return DaemonCommand(status->parsed() ? "status" : "stop", daemonDir, asJson);
  if (!translate->parsed()) return Usage("no command given");
  const bool useDaemon = !noDaemon && std::getenv("CROSSRT_NO_DAEMON") == nullptr;
  for (const std::string& v : request.compositions)
    if (v.find('=') == std::string::npos || v.front() == '=' || v.back() == '=')
      return Usage("--compose takes Interface=Implementation, e.g. ISceneObject=BVHScene, not '" + v + "'");
  if (!virtualLevel.empty()) {
    if (virtualLevel != "1" && virtualLevel != "2" && virtualLevel != "3")
      return Usage("--virtual-level takes 1 (one array of equal slots), 2 (a buffer per class) or 3 (2, plus callable and intersection shaders), not '" +
                   virtualLevel + "'");
    request.virtualLevel = std::stoi(virtualLevel);
  }
  if (!executionMode.empty()) {
    if (executionMode != "megakernel" && executionMode != "wavefront")
      return Usage("--execution-mode takes megakernel (one shader per thread loop) or wavefront (one dispatch per kernel call), not '" +
                   executionMode + "'");
    request.megakernel = executionMode == "megakernel";
  }
  if (const std::string& v = request.generatedName;
      translate->count("--name") && (v.empty() || !(std::isalpha((unsigned char)v[0]) || v[0] == '_') ||
                                     v.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") != std::string::npos))
    return Usage("--name takes a C++ identifier (the generated class's name), not '" + v + "'");
  if (request.sources.empty() && candidates.empty()) return Usage("at least one --source (or --candidate) is required");
  if (!engine::ParseBackend(backend, request.backend)) return Usage("--backend must be 'vulkan', 'cpu' or 'ispc', not '" + backend + "'");
  if (!candidates.empty()) {
    std::vector<std::string> includeDirs;
    for (size_t i = 0; i < request.compileArgs.size(); ++i) {
      const std::string& a = request.compileArgs[i];
      if ((a == "-I" || a == "-iquote") && i + 1 < request.compileArgs.size()) includeDirs.push_back(request.compileArgs[i + 1]);
      else if (a.rfind("-I", 0) == 0 && a.size() > 2) includeDirs.push_back(a.substr(2));
    }
    // Relative candidates are the target's sources, named from its source folder.
    for (auto& c : candidates)
      if (!c.empty() && c[0] != '/' && !sourceDir.empty()) c = sourceDir + "/" + c;
    auto found = crossrt::client::FindClassSources(request.className, candidates, includeDirs);
    if (found.sources.empty()) {
      std::cerr << "crossrt: error: " << found.error << "\n";
      return 1;
    }
    request.sources.insert(request.sources.end(), found.sources.begin(), found.sources.end());
  }

  MakePathsAbsolute(request);
  crossrt::client::RecordRequest(request, buildDir);  // for the language server
  // Unchanged key: nothing to translate, nothing to write.
  if (crossrt::client::UpToDate(request)) return 0;

  engine::TranslateResult result;
  bool translated = false;
  if (const char* env = std::getenv("CROSSRT_REMOTE_STORAGE")) remoteStorage = env;
  crossrt::client::RemoteCache remote(remoteStorage, sourceRoot, buildDir, remoteKeyFile);
  const bool fromRemote = remote.Enabled() && remote.Fetch(request, result);
  translated = fromRemote;
  if (!translated && useDaemon && !buildDir.empty()) {
    DaemonClient daemon(buildDir);
    auto response = daemon.Call({{"command", "translate"}, {"request", crossrt::protocol::ToJson(request)}}, /*start=*/true);
    std::string why = response ? response->value("error", "unknown error") : daemon.Error();
    if (response && response->value("ok", false)) {
      try {
        result = crossrt::protocol::ResultFromJson(*response);
        translated = true;
      } catch (const std::exception& e) {
        why = std::string("unreadable answer: ") + e.what();
      }
    }
    if (!translated)
      std::cerr << "crossrt: note: translation daemon unavailable (" << why << "); translating in-process\n";
  }
  if (!translated) {
    try {
      result = crossrt::client::TranslateInProcess(request);
    } catch (const std::exception& e) {
      std::cerr << "crossrt: internal error while translating '" << request.className << "': " << e.what() << "\n";
      return 1;
    }
  }
  std::cerr << result.diagnostics;
  if (!result.ok) {
    std::cerr << "crossrt: translation of class '" << request.className << "' failed\n";
    return 1;
  }
  try {
    crossrt::client::WriteOutputs(request, result);
    crossrt::client::WriteManifest(request, result);
  } catch (const std::exception& e) {
    std::cerr << "crossrt: error: " << e.what() << "\n";
    return 1;
  }
  if (!fromRemote && remote.Enabled()) remote.Store(request, result);
  // The engine is an input too (the daemon and the library the client loads): a rebuilt or upgraded
  // CrossRT translates again, in the build tree and against an installed package alike.
  std::vector<std::string> inputs = result.inputs;
  for (const std::string& engine : {crossrt::client::DaemonExecutable(), crossrt::client::EnginePath()})
    if (!engine.empty() && access(engine.c_str(), R_OK) == 0) inputs.push_back(std::filesystem::weakly_canonical(engine).string());
  if (!depfile.empty() && !WriteDepfile(depfile, depfileTarget.empty() ? depfile : depfileTarget, inputs)) {
    std::cerr << "crossrt: error: cannot write depfile '" << depfile << "'\n";
    return 1;
  }
  return 0;
}
