// The language server (LanguageServer.h): the protocol's messages on the main thread, translations
// and the answers that need them on one worker thread. Both share the documents and the classes
// under one mutex; what they send is queued under it and written outside it, so that a client
// slow to read never stalls the reading of its own messages.
#include "LanguageServer.h"

#include "parse/AstCache.h"
#include "BuildTree.h"
#include "CompilerText.h"
#include "GeneratedCode.h"
#include "Model.h"
#include "QuickFixes.h"
#include "compile/Spirv.h"
#include "Text.h"
#include "Translator.h"
#include "Transport.h"

#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <ctime>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <regex>
#include <set>
#include <thread>

namespace crossrt::lsp {

namespace {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

enum ErrorCode {
  kParseError = -32700,
  kInvalidRequest = -32600,
  kMethodNotFound = -32601,
  kInvalidParams = -32602,
  kInternalError = -32603,
  kServerNotInitialized = -32002,
  kRequestCancelled = -32800,
};

// A request's parameters are the client's to get wrong: every field is looked up with a check, and
// a field of the wrong kind reads as missing.
const json& Field(const json& j, const char* name) {
  static const json none;
  if (!j.is_object()) return none;
  auto it = j.find(name);
  return it == j.end() ? none : *it;
}
std::string StringField(const json& j, const char* name) {
  const json& f = Field(j, name);
  return f.is_string() ? f.get<std::string>() : "";
}
unsigned NumberField(const json& j, const char* name) {
  const json& f = Field(j, name);
  if (!f.is_number_integer() && !f.is_number_unsigned()) return 0;
  const long long v = f.get<long long>();
  return v < 0 ? 0 : v > (1 << 30) ? (1u << 30) : unsigned(v);
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return in ? std::string(std::istreambuf_iterator<char>(in), {}) : std::string();
}

std::string Phases(const std::map<std::string, double>& timings) {
  std::string out;
  for (auto& [phase, ms] : timings) out += (out.empty() ? "" : ", ") + phase + " " + std::to_string(int(ms));
  return out;
}

const char* BackendLabel(engine::Backend b) {
  return b == engine::Backend::Vulkan ? "Vulkan" : b == engine::Backend::Cpu ? "CPU" : "ISPC";
}

json Position(unsigned line, unsigned character) { return {{"line", line}, {"character", character}}; }
json Range(unsigned line, unsigned from, unsigned to) { return {{"start", Position(line, from)}, {"end", Position(line, to)}}; }

struct Document {
  std::string uri, text;
  long long version = 0;
};

// One class translation the build asks for (one backend), and what its last translation here said.
struct Job {
  ClassRequest cls;
  bool dirty = false;
  bool translatedHere = false;                  // its inputs are what this server's translation read
  Clock::time_point due;
  std::vector<CompilerDiagnostic> diagnostics;  // their files are real paths
  bool hasModel = false;                        // from the last translation that analysed
  engine::ClassModel model;
  std::map<std::string, std::string> files;     // generated, by name, written to GeneratedFolder(cls.key)
};

// A user function the models know: a kernel or a control function.
struct Function {
  const Job* job;
  std::string name, kind;  // kind: "kernel" or "control function"
  const engine::SourcePlace* at;
  const engine::Kernel* kernel = nullptr;
  const engine::Control* control = nullptr;
};

class Server {
public:
  Server(const ServerOptions& options, int in, int out) : m_options(options), m_io(in, out) {}
  int Run();

private:
  bool OnMessage(const std::string& body);  // false: exit
  void OnRequest(const json& id, const std::string& method, const json& params);
  void Release();  // the reader's staged requests to the worker
  bool OnNotification(const std::string& method, const json& params);
  json Initialize(const json& params);
  void Edit(const std::string& method, const json& params);

  void Work();
  void RunJob(std::shared_ptr<Job> held, std::unique_lock<std::mutex>& lock);
  json Answer(const std::string& method, const json& params);
  json Hover(const std::string& path, unsigned line, unsigned character);
  json CodeLenses(const std::string& path);
  json Definition(const std::string& path, unsigned line);
  json CodeActions(const std::string& uri, const std::string& path, const json& params);
  json ShowGenerated(const json& params);

  // Under the lock.
  void Rescan(bool force);
  void MarkDirty(const std::string& path, Clock::time_point due);
  // `versions`: the documents' versions the diagnostics were computed from (default: the current ones).
  void Publish(const std::set<std::string>& paths, const std::map<std::string, long long>* versions = nullptr);
  std::string TextOf(const std::string& path);
  std::vector<Function> FunctionsIn(const std::string& path);
  std::string Resolve(const std::string& file, const Job& job);
  std::string Describe(const Function& f, const Job& job);
  std::pair<std::string, unsigned> GeneratedPlace(const Job& job, const std::string& qualified, bool kernel);

  void Queue(json message) { m_outbox.push_back(std::move(message)); }
  void Send();  // writes what is queued; never under the lock
  void Reply(const json& id, json result) { m_io.Write({{"jsonrpc", "2.0"}, {"id", id}, {"result", std::move(result)}}); }
  void Error(const json& id, int code, const std::string& message) {
    m_io.Write({{"jsonrpc", "2.0"}, {"id", id}, {"error", {{"code", code}, {"message", message}}}});
  }
  void Log(const std::string& message);

  ServerOptions m_options;
  Transport m_io;
  std::mutex m_mutex;
  std::condition_variable m_wake;
  std::vector<json> m_outbox;
  std::map<std::string, Document> m_docs;  // by real path
  std::vector<std::shared_ptr<Job>> m_jobs;  // shared: a translation in flight keeps its job
  std::vector<std::string> m_buildTrees;
  Clock::time_point m_lastScan;
  struct Pending {
    json id;
    std::string method;
    json params;
  };
  std::deque<Pending> m_requests;
  std::vector<Pending> m_staged;             // read, not yet handed to the worker (the reader's own)
  std::set<std::string> m_cancelled;         // request ids, as JSON text
  std::map<std::string, json> m_published;   // path -> the diagnostics last sent
  std::set<std::string> m_toldUnknown;       // files said to belong to no class
  bool m_initialized = false, m_shutdown = false, m_stop = false, m_showDocument = false;
  int m_nextRequest = 1;
  engine::AstCache m_cache{64, engine::AstCache::LayerPreparation::AfterParse};
  engine::SpirvCache m_spirv;
  std::mutex m_logMutex;
  std::ofstream m_log;
};

void Server::Log(const std::string& message) {
  std::lock_guard<std::mutex> guard(m_logMutex);
  if (!m_log.is_open()) return;
  std::time_t t = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%H:%M:%S", std::localtime(&t));
  m_log << stamp << " " << message << std::endl;
}

void Server::Send() {
  std::vector<json> out;
  {
    std::lock_guard<std::mutex> guard(m_mutex);
    out.swap(m_outbox);
  }
  for (auto& message : out) m_io.Write(message);
}

int Server::Run() {
  if (!m_options.logPath.empty()) m_log.open(m_options.logPath, std::ios::app);
  Log("crossrtd --lsp started");
  m_io.BeforeWaiting([this] { Release(); });
  std::thread worker([this] { Work(); });
  int code = 1;
  for (;;) {
    std::string body;
    const ReadStatus status = m_io.Read(body);
    if (status == ReadStatus::Closed) {
      Log("the client went away");
      code = m_shutdown ? 0 : 1;
      break;
    }
    if (status == ReadStatus::Malformed) {
      Log("malformed message: " + body);
      Error(nullptr, kInvalidRequest, "malformed message: " + body);
      continue;
    }
    bool goOn = true;
    try {
      goOn = OnMessage(body);
    } catch (const std::exception& e) {  // a handler's bug must not take the server down
      Log(std::string("internal error: ") + e.what());
    }
    Send();
    if (!goOn) {
      code = m_shutdown ? 0 : 1;
      break;
    }
  }
  {
    std::lock_guard<std::mutex> guard(m_mutex);
    m_stop = true;
  }
  m_wake.notify_all();
  Log("exiting with " + std::to_string(code));
  if (m_log.is_open()) m_log.flush();
  // A translation in flight is abandoned, not waited for.
  std::_Exit(code);
}

bool Server::OnMessage(const std::string& body) {
  json message;
  try {
    message = json::parse(body);
  } catch (const std::exception& e) {
    Error(nullptr, kParseError, std::string("not JSON: ") + e.what());
    return true;
  }
  if (!message.is_object()) {
    Error(nullptr, kInvalidRequest, "a message is a JSON object");
    return true;
  }
  const json& id = Field(message, "id");
  const bool hasId = message.contains("id");
  if (hasId && !id.is_number_integer() && !id.is_string()) {
    Error(nullptr, kInvalidRequest, "a request's id is a number or a string");
    return true;
  }
  const json& method = Field(message, "method");
  if (!method.is_string()) {
    if (hasId && (message.contains("result") || message.contains("error"))) return true;  // the client answers one of ours
    Error(hasId ? id : json(nullptr), kInvalidRequest, "a message without a method");
    return true;
  }
  const json& params = Field(message, "params");
  if (hasId) {
    try {
      OnRequest(id, method.get<std::string>(), params);
    } catch (const std::exception& e) {
      Error(id, kInternalError, e.what());
    }
    return true;
  }
  return OnNotification(method.get<std::string>(), params);
}

void Server::OnRequest(const json& id, const std::string& method, const json& params) {
  if (method == "initialize") {
    if (m_initialized) return Error(id, kInvalidRequest, "initialize was already received");
    json result = Initialize(params);
    Reply(id, result);
    return;
  }
  if (!m_initialized) return Error(id, kServerNotInitialized, "the first request must be initialize");
  if (method == "shutdown") {
    m_shutdown = true;
    return Reply(id, nullptr);
  }
  if (m_shutdown) return Error(id, kInvalidRequest, "shutdown was requested: only exit is expected");
  static const std::set<std::string> answered = {"textDocument/hover", "textDocument/codeLens", "textDocument/definition",
                                                 "textDocument/codeAction", "workspace/executeCommand"};
  if (!answered.count(method)) return Error(id, kMethodNotFound, "crossrtd does not answer '" + method + "'");
  m_staged.push_back({id, method, params});  // the worker gets it once the reader has caught up (Release)
}

// Hands the requests read so far to the worker. The reader calls it when it has read every message
// received and is about to wait for more, so that a $/cancelRequest sent with its request always
// finds it unanswered: handed over one at a time, the worker, woken by the request, could answer it
// before the reader had read the cancel that came in the same write (lsp.protocol failed so
// beside two busy threads, once in 12 runs).
void Server::Release() {
  if (m_staged.empty()) return;
  {
    std::lock_guard<std::mutex> guard(m_mutex);
    for (auto& request : m_staged) m_requests.push_back(std::move(request));
  }
  m_staged.clear();
  m_wake.notify_all();
}

bool Server::OnNotification(const std::string& method, const json& params) {
  if (method == "exit") return false;
  if (!m_initialized) return true;  // dropped, as the protocol says
  if (method == "$/cancelRequest") {
    const json& id = Field(params, "id");
    if (id.is_number_integer() || id.is_string()) {
      std::lock_guard<std::mutex> guard(m_mutex);
      if (m_cancelled.size() > 4096) m_cancelled.clear();  // cancels of requests long answered
      m_cancelled.insert(id.dump());
    }
    return true;
  }
  if (method.rfind("textDocument/did", 0) == 0) Edit(method, params);
  return true;  // initialized, configuration changes and the rest: nothing to do
}

json Server::Initialize(const json& params) {
  std::vector<std::string> trees = m_options.buildDirs;
  const json& options = Field(Field(params, "initializationOptions"), "buildDirectory");
  if (options.is_string()) trees.push_back(options.get<std::string>());
  if (options.is_array())
    for (auto& o : options)
      if (o.is_string()) trees.push_back(o.get<std::string>());
  std::vector<std::string> roots;
  if (std::string root = PathOfUri(StringField(params, "rootUri")); !root.empty()) roots.push_back(root);
  if (std::string root = StringField(params, "rootPath"); !root.empty()) roots.push_back(root);
  if (Field(params, "workspaceFolders").is_array())
    for (auto& folder : Field(params, "workspaceFolders"))
      if (std::string root = PathOfUri(StringField(folder, "uri")); !root.empty()) roots.push_back(root);
  for (auto& root : roots)
    for (auto& tree : FindBuildTrees(root)) trees.push_back(tree);
  for (auto& t : trees) t = RealPath(t);
  std::sort(trees.begin(), trees.end());
  trees.erase(std::unique(trees.begin(), trees.end()), trees.end());
  const json& support = Field(Field(Field(params, "capabilities"), "window"), "showDocument");
  {
    std::lock_guard<std::mutex> guard(m_mutex);
    m_buildTrees = trees;
    m_showDocument = Field(support, "support").is_boolean() && Field(support, "support").get<bool>();
    m_initialized = true;
    Rescan(true);
    std::string names;
    for (auto& t : trees) names += " " + t;
    Log("build trees:" + (names.empty() ? std::string(" none") : names) + "; " + std::to_string(m_jobs.size()) + " class translations");
  }
  return {{"capabilities",
           {{"textDocumentSync", {{"openClose", true}, {"change", 2}, {"save", {{"includeText", false}}}}},
            {"hoverProvider", true},
            {"codeLensProvider", {{"resolveProvider", false}}},
            {"definitionProvider", true},
            {"codeActionProvider", {{"codeActionKinds", {"quickfix"}}}},
            {"executeCommandProvider", {{"commands", {"crossrt.showGenerated"}}}}}},
          {"serverInfo", {{"name", "crossrtd"}, {"version", engine::TranslatorVersion()}}}};
}

void Server::Edit(const std::string& method, const json& params) {
  const json& document = Field(params, "textDocument");
  const std::string uri = StringField(document, "uri"), raw = PathOfUri(uri);
  if (raw.empty()) return;  // not a file: not ours
  const std::string path = RealPath(raw);
  std::lock_guard<std::mutex> guard(m_mutex);
  const Clock::time_point now = Clock::now();
  if (method == "textDocument/didOpen") {
    const json& text = Field(document, "text");
    if (!text.is_string()) return;
    m_docs[path] = {uri, text.get<std::string>(), Field(document, "version").is_number_integer() ? Field(document, "version").get<long long>() : 0};
    bool known = false;
    for (auto& job : m_jobs) known |= job->cls.inputs.count(path) > 0;
    if (!known) Rescan(false);
    known = false;
    for (auto& job : m_jobs) known |= job->cls.inputs.count(path) > 0;
    // A header of a class whose build translation failed before it recorded what it read: the
    // classes not yet translated here, with a source in its folder, may include it.
    const std::string folder = std::filesystem::path(path).parent_path().string();
    for (auto& job : m_jobs)
      for (auto& s : job->cls.request.sources)
        if (!job->translatedHere && std::filesystem::path(RealPath(s)).parent_path() == folder) job->dirty = true, job->due = now;
    if (!known && m_toldUnknown.insert(path).second)
      Log(path + " belongs to no class translation the build trees record yet (build once after crossrt_add_class)");
    MarkDirty(path, now);
  } else if (method == "textDocument/didChange") {
    auto doc = m_docs.find(path);
    const json& changes = Field(params, "contentChanges");
    if (doc == m_docs.end() || !changes.is_array()) return;
    for (auto& change : changes) {
      const json& text = Field(change, "text");
      if (!text.is_string()) continue;
      const json& range = Field(change, "range");
      if (range.is_null()) {
        doc->second.text = text.get<std::string>();
        continue;
      }
      const json &start = Field(range, "start"), &end = Field(range, "end");
      size_t from = OffsetOfPosition(doc->second.text, NumberField(start, "line"), NumberField(start, "character"));
      size_t to = OffsetOfPosition(doc->second.text, NumberField(end, "line"), NumberField(end, "character"));
      if (to < from) std::swap(from, to);
      doc->second.text.replace(from, to - from, text.get<std::string>());
    }
    if (Field(document, "version").is_number_integer()) doc->second.version = Field(document, "version").get<long long>();
    MarkDirty(path, now + std::chrono::milliseconds(m_options.debounceMs));
  } else if (method == "textDocument/didSave") {
    if (auto doc = m_docs.find(path); doc != m_docs.end() && Field(params, "text").is_string())
      doc->second.text = Field(params, "text").get<std::string>();
    Rescan(false);  // a build may have recorded classes since
    MarkDirty(path, now);
  } else if (method == "textDocument/didClose") {
    m_docs.erase(path);
    MarkDirty(path, now);  // as it is on disk
  }
  m_wake.notify_all();
}

void Server::Rescan(bool force) {
  const Clock::time_point now = Clock::now();
  if (!force && now - m_lastScan < std::chrono::seconds(2)) return;
  m_lastScan = now;
  std::string problems;
  std::vector<ClassRequest> found = FindClassRequests(m_buildTrees, problems);
  if (!problems.empty()) Log("unreadable class records:\n" + problems);
  std::map<std::string, std::shared_ptr<Job>> old;
  for (auto& job : m_jobs) old[job->cls.key] = std::move(job);
  m_jobs.clear();
  for (auto& c : found) {
    auto it = old.find(c.key);
    std::shared_ptr<Job> job;
    if (it != old.end()) {
      job = std::move(it->second);
      old.erase(it);
      c.inputs.insert(job->cls.inputs.begin(), job->cls.inputs.end());
    } else {
      job = std::make_shared<Job>();
      for (auto& [path, doc] : m_docs)
        if (c.inputs.count(path)) job->dirty = true, job->due = now;
    }
    job->cls = std::move(c);
    m_jobs.push_back(std::move(job));
  }
  std::set<std::string> gone;  // the diagnostics of classes the build no longer has
  for (auto& [key, job] : old)
    for (auto& d : job->diagnostics) gone.insert(d.at.file);
  old.clear();
  Publish(gone);
}

void Server::MarkDirty(const std::string& path, Clock::time_point due) {
  for (auto& job : m_jobs)
    if (job->cls.inputs.count(path)) {
      job->dirty = true;
      job->due = due;
    }
}

std::string Server::TextOf(const std::string& path) {
  auto doc = m_docs.find(path);
  return doc != m_docs.end() ? doc->second.text : ReadFile(path);
}

// A diagnostic's file as a real path: Clang's spelling, a bare name of one of the class's inputs,
// or (no file) the class's first source.
std::string Server::Resolve(const std::string& file, const Job& job) {
  if (file.empty()) return job.cls.request.sources.empty() ? "" : RealPath(job.cls.request.sources.front());
  if (file[0] == '/') return RealPath(file);
  for (auto& input : job.cls.inputs)
    if (std::filesystem::path(input).filename() == file) return input;
  return job.cls.request.sources.empty() ? "" : RealPath(job.cls.request.sources.front());
}

void Server::Work() {
  std::unique_lock<std::mutex> lock(m_mutex);
  while (!m_stop) {
    if (!m_requests.empty()) {
      Pending request = std::move(m_requests.front());
      m_requests.pop_front();
      // Edits not yet translated first: the answer is about the text the client has.
      for (size_t i = 0; i < m_jobs.size(); ++i)
        if (m_jobs[i]->dirty) RunJob(m_jobs[i], lock);
      if (m_cancelled.erase(request.id.dump())) {
        Queue({{"jsonrpc", "2.0"}, {"id", request.id}, {"error", {{"code", kRequestCancelled}, {"message", "cancelled"}}}});
      } else {
        try {
          Queue({{"jsonrpc", "2.0"}, {"id", request.id}, {"result", Answer(request.method, request.params)}});
        } catch (const std::exception& e) {
          Queue({{"jsonrpc", "2.0"}, {"id", request.id}, {"error", {{"code", kInvalidParams}, {"message", e.what()}}}});
        }
      }
      lock.unlock();
      Send();
      lock.lock();
      continue;
    }
    const Clock::time_point now = Clock::now();
    std::shared_ptr<Job> next;
    Clock::time_point earliest = Clock::time_point::max();
    for (auto& job : m_jobs)
      if (job->dirty) {
        if (job->due <= now) {
          next = job;
          break;
        }
        earliest = std::min(earliest, job->due);
      }
    if (next) {
      RunJob(next, lock);
      continue;
    }
    if (earliest == Clock::time_point::max()) m_wake.wait(lock);
    else m_wake.wait_until(lock, earliest);
  }
}

// Translates with the editor's buffers, publishes what changed, then writes the generated files
// to the server's own folder. Called and returns with the lock held; translates without it.
void Server::RunJob(std::shared_ptr<Job> held, std::unique_lock<std::mutex>& lock) {
  Job& job = *held;
  engine::TranslateRequest request = job.cls.request;
  std::map<std::string, long long> versions;  // of the text translated: an edit may arrive meanwhile
  for (auto& [path, doc] : m_docs) {
    request.unsavedFiles[path] = doc.text;
    versions[path] = doc.version;
  }
  job.dirty = false;
  const std::string folder = GeneratedFolder(job.cls.key);
  lock.unlock();
  const Clock::time_point t0 = Clock::now();
  engine::TranslateResult result;
  auto model = std::make_unique<engine::ClassModel>();
  try {
    result = engine::Translate(request, &m_cache, &m_spirv, model.get());
  } catch (const std::exception& e) {
    result.diagnostics = std::string("error: internal error of the translator: ") + e.what() + "\n";
  }
  const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  std::vector<CompilerDiagnostic> diagnostics = ParseCompilerText(result.diagnostics);
  lock.lock();
  Log("translated " + request.className + " (" + engine::BackendName(request.backend) + "): " +
      (result.ok ? "ok" : result.parseFailed ? "does not parse" : "errors") + ", " + std::to_string(diagnostics.size()) +
      " diagnostics, " + std::to_string(int(ms)) + " ms (" + Phases(result.timingsMs) + ")");
  for (auto& in : result.inputs) job.cls.inputs.insert(in);
  job.translatedHere = true;
  if (result.parseFailed) return;  // clangd shows the compiler's errors; the translator's stay until it parses
  for (auto& d : diagnostics) {
    d.at.file = Resolve(d.at.file, job);
    for (auto& [place, message] : d.related) place.file = Resolve(place.file, job);
  }
  std::set<std::string> touched;
  for (auto& d : job.diagnostics) touched.insert(d.at.file);
  for (auto& d : diagnostics) touched.insert(d.at.file);
  job.diagnostics = std::move(diagnostics);
  if (result.ok) {
    job.model = std::move(*model);
    job.hasModel = true;
    job.files = result.files;
  }
  Publish(touched, &versions);
  lock.unlock();
  Send();
  if (result.ok) WriteGenerated(folder, result.files);
  lock.lock();
}

void Server::Publish(const std::set<std::string>& paths, const std::map<std::string, long long>* versions) {
  for (const std::string& path : paths) {
    if (path.empty()) continue;
    // One diagnostic per place and message, however many backends report it.
    struct Merged {
      const CompilerDiagnostic* d;
      std::vector<std::string> backends;
    };
    std::map<std::tuple<unsigned, unsigned, int, std::string, std::string>, Merged> merged;
    for (auto& job : m_jobs)
      for (auto& d : job->diagnostics)
        if (d.at.file == path) {
          auto& m = merged.try_emplace({d.at.line, d.at.column, int(d.severity), d.message, d.hint}, Merged{&d, {}}).first->second;
          const std::string backend = engine::BackendName(job->cls.request.backend);
          if (std::find(m.backends.begin(), m.backends.end(), backend) == m.backends.end()) m.backends.push_back(backend);
        }
    const std::string text = TextOf(path);
    auto range = [&](const std::string& file, unsigned line, unsigned column) {
      if (line == 0) return Range(0, 0, 0);
      const std::string source = file == path ? text : TextOf(file);
      const std::string lineText = LineOf(source, line - 1);
      size_t end = column == 0 ? 0 : column - 1;
      while (end < lineText.size() && (std::isalnum((unsigned char)lineText[end]) || lineText[end] == '_')) ++end;
      const unsigned from = CharacterOfColumn(source, line - 1, column == 0 ? 0 : column - 1);
      return Range(line - 1, from, std::max(from + 1, CharacterOfColumn(source, line - 1, unsigned(end))));
    };
    json list = json::array();
    for (auto& [key, m] : merged) {
      const CompilerDiagnostic& d = *m.d;
      std::string backends;
      for (auto& b : m.backends) backends += (backends.empty() ? "" : ", ") + b;
      json diagnostic = {{"range", range(path, d.at.line, d.at.column)},
                         {"severity", int(d.severity)},
                         {"source", "crossrt (" + backends + ")"},
                         {"message", d.message + (d.hint.empty() ? "" : "\nhint: " + d.hint)}};
      if (!d.related.empty()) {
        json related = json::array();
        for (auto& [place, message] : d.related)
          if (!place.file.empty())
            related.push_back({{"location", {{"uri", UriOfPath(place.file)}, {"range", range(place.file, place.line, place.column)}}},
                               {"message", message}});
        if (!related.empty()) diagnostic["relatedInformation"] = related;
      }
      list.push_back(diagnostic);
    }
    json& last = m_published[path];
    if (last == list || (last.is_null() && list.empty())) continue;
    last = list;
    auto doc = m_docs.find(path);
    json params = {{"uri", doc != m_docs.end() ? doc->second.uri : UriOfPath(path)}, {"diagnostics", list}};
    if (doc != m_docs.end()) {
      long long version = doc->second.version;
      if (versions)
        if (auto translated = versions->find(path); translated != versions->end()) version = translated->second;
      params["version"] = version;
    }
    Queue({{"jsonrpc", "2.0"}, {"method", "textDocument/publishDiagnostics"}, {"params", params}});
  }
}

json Server::Answer(const std::string& method, const json& params) {
  const std::string uri = StringField(Field(params, "textDocument"), "uri"), raw = PathOfUri(uri);
  const std::string path = raw.empty() ? "" : RealPath(raw);
  const json& position = Field(params, "position");
  if (method == "workspace/executeCommand") return ShowGenerated(params);
  if (path.empty()) throw std::runtime_error("textDocument.uri is not a file URI");
  if (method == "textDocument/hover") return Hover(path, NumberField(position, "line"), NumberField(position, "character"));
  if (method == "textDocument/codeLens") return CodeLenses(path);
  if (method == "textDocument/definition") return Definition(path, NumberField(position, "line"));
  return CodeActions(uri, path, params);
}

std::vector<Function> Server::FunctionsIn(const std::string& path) {
  std::vector<Function> out;
  for (auto& job : m_jobs) {
    if (!job->hasModel) continue;
    for (auto& k : job->model.kernels)
      if (!k.definedAt.file.empty() && RealPath(k.definedAt.file) == path) out.push_back({job.get(), k.name, "kernel", &k.definedAt, &k, nullptr});
    for (auto& c : job->model.controls)
      if (!c.definedAt.file.empty() && RealPath(c.definedAt.file) == path)
        out.push_back({job.get(), c.name, "control function", &c.definedAt, nullptr, &c});
  }
  return out;
}

// Where the generated code of `qualified` is: for a kernel, its shader on Vulkan and its ISPC
// function on ISPC, else the class's source; ("", 0) when no file marks it.
std::pair<std::string, unsigned> Server::GeneratedPlace(const Job& job, const std::string& qualified, bool kernel) {
  std::vector<std::string> order;
  const std::string name = qualified.substr(qualified.rfind(':') + 1);
  if (kernel && job.cls.request.backend == engine::Backend::Vulkan) order.push_back("shaders/" + name + ".comp");
  for (auto& [file, text] : job.files)
    if (kernel && file.size() > 5 && file.compare(file.size() - 5, 5, ".ispc") == 0) order.push_back(file);
  for (auto& [file, text] : job.files)
    if (file.size() > 4 && file.compare(file.size() - 4, 4, ".cpp") == 0) order.push_back(file);
  for (auto& file : order) {
    auto it = job.files.find(file);
    if (it == job.files.end()) continue;
    if (unsigned line = LineGeneratedFrom(it->second, qualified)) return {file, line};
  }
  return {"", 0};
}

std::string Server::Describe(const Function& f, const Job& job) {
  const std::string qualified = job.model.className + "::" + f.name;
  auto [file, line] = GeneratedPlace(job, qualified, f.kernel != nullptr);
  const std::string link = file.empty() ? "" : " ([" + std::filesystem::path(file).filename().string() + "](" +
                                                   UriOfPath(GeneratedFolder(job.cls.key) + "/" + file) + "#L" + std::to_string(line) + "))";
  std::string s = "- **" + std::string(BackendLabel(job.cls.request.backend)) + "** (" + job.model.generatedName + "): ";
  const bool vulkan = job.cls.request.backend == engine::Backend::Vulkan;
  if (const engine::Kernel* k = f.kernel) {
    std::string over;
    for (auto& loop : k->loops) over += (over.empty() ? "" : ", ") + loop.var + " < " + loop.countCpp;
    if (vulkan) {
      auto shader = job.files.find("shaders/" + k->name + ".comp");
      const ShaderFacts facts = shader == job.files.end() ? ShaderFacts{} : ReadShader(shader->second);
      s += k->rtv ? "a compute shader run per thread of its control function's loop" : "a " + std::to_string(k->dims) + "D compute dispatch";
      if (facts.group[0]) s += " in workgroups of " + std::to_string(facts.group[0]) + "x" + std::to_string(facts.group[1]) + "x" + std::to_string(facts.group[2]);
      if (!over.empty()) s += ", a thread per " + over;
      s += link;
      for (auto& b : facts.buffers)
        s += "\n  - buffer " + std::to_string(b.binding) + ": " + (b.what.empty() ? "`" + b.name + "`" : b.what) + " (`" + b.name + "[]`, " + b.access + ")";
    } else {
      const bool ispc = job.cls.request.backend == engine::Backend::Ispc;
      s += k->rtv ? "called per thread of its control function's loop"
                  : std::string(ispc ? "its loop nest in SIMD lanes (foreach) over chunks on all cores" : "its loop nest on all cores (crossrt::ParallelFor)");
      if (!over.empty()) s += ", " + over;
      s += link;
    }
    for (auto& r : k->reductions)
      s += "\n  - a reduction (" + std::string(r.op == engine::ReduceOp::Add ? "+" : r.op == engine::ReduceOp::Sub ? "-" : r.op == engine::ReduceOp::Min ? "min" : "max") +
           ") into `" + r.member + "`" + (r.local ? " (a local)" : "");
  } else if (const engine::Control* c = f.control) {
    std::string kernels;
    for (auto& k : c->kernelsCalled) kernels += (kernels.empty() ? "`" : ", `") + k + "`";
    s += vulkan ? "records its kernels into a command buffer" : "runs on the host as written";
    if (!kernels.empty()) s += "; calls " + kernels;
    if (vulkan && c->synchronizes) s += "; waits for the GPU where host code reads what kernels wrote";
    if (vulkan && c->hasHostTail) s += "; runs the code after its last kernel once the results are back";
    s += link;
  }
  return s;
}

// On the name of a kernel or control function of a class this file belongs to: where it is
// defined, declared or called.
json Server::Hover(const std::string& path, unsigned line, unsigned character) {
  const std::string text = TextOf(path);
  const size_t lineStart = OffsetOfPosition(text, line, 0), at = OffsetOfPosition(text, line, character);
  auto word = [&](size_t i) { return i < text.size() && (std::isalnum((unsigned char)text[i]) || text[i] == '_'); };
  size_t begin = at, end = at;
  while (begin > lineStart && word(begin - 1)) --begin;
  while (word(end)) ++end;
  if (begin == end) return nullptr;
  const std::string name = text.substr(begin, end - begin);
  std::string body;
  std::set<std::string> said;  // a build tree may translate a class alike in several places
  for (auto& job : m_jobs) {
    if (!job->hasModel || !job->cls.inputs.count(path)) continue;
    std::vector<Function> named;
    for (auto& k : job->model.kernels)
      if (k.name == name) named.push_back({job.get(), k.name, "kernel", &k.definedAt, &k, nullptr});
    for (auto& c : job->model.controls)
      if (c.name == name) named.push_back({job.get(), c.name, "control function", &c.definedAt, nullptr, &c});
    for (const Function& f : named) {
      const std::string description = Describe(f, *f.job);
      static const std::regex link(R"(\]\(file://[^)]*\))");  // the same words, linking another folder's files
      if (!said.insert(std::regex_replace(description, link, "]")).second) continue;
      if (body.empty()) body = "**" + f.name + "**: a " + f.kind + " of " + f.job->model.className + " that CrossRT translates\n";
      body += "\n" + description;
    }
  }
  if (body.empty()) return nullptr;
  const unsigned from = CharacterOfColumn(text, line, unsigned(begin - lineStart)), to = CharacterOfColumn(text, line, unsigned(end - lineStart));
  return {{"contents", {{"kind", "markdown"}, {"value", body}}}, {"range", Range(line, from, to)}};
}

json Server::CodeLenses(const std::string& path) {
  const std::string text = TextOf(path);
  json lenses = json::array();
  std::set<std::pair<unsigned, std::string>> said;  // (line, title): one lens for a class translated alike twice
  for (const Function& f : FunctionsIn(path)) {
    auto [file, line] = GeneratedPlace(*f.job, f.job->model.className + "::" + f.name, f.kernel != nullptr);
    if (file.empty()) continue;
    const std::string title = std::string("CrossRT ") + BackendLabel(f.job->cls.request.backend) + ": " + std::filesystem::path(file).filename().string();
    if (!said.insert({f.at->line, title}).second) continue;
    const unsigned from = CharacterOfColumn(text, f.at->line - 1, f.at->column - 1);
    lenses.push_back({{"range", Range(f.at->line - 1, from, from + unsigned(f.name.size()))},
                      {"command",
                       {{"title", title},
                        {"command", "crossrt.showGenerated"},
                        {"arguments", {{{"uri", UriOfPath(GeneratedFolder(f.job->cls.key) + "/" + file)}, {"line", line}}}}}}});
  }
  return lenses;
}

json Server::Definition(const std::string& path, unsigned line) {
  const std::string text = TextOf(path);
  if (text.substr(0, 400).find("generated by CrossRT") == std::string::npos) return nullptr;  // the user's code: clangd's
  const std::string qualified = FunctionAtLine(text, line + 1);
  if (qualified.empty()) return nullptr;
  for (auto& job : m_jobs) {
    if (!job->hasModel) continue;
    auto place = [&](const std::string& name, const engine::SourcePlace& at) -> json {
      if (job->model.className + "::" + name != qualified || at.file.empty()) return nullptr;
      const std::string file = RealPath(at.file);
      const unsigned from = CharacterOfColumn(TextOf(file), at.line - 1, at.column - 1);
      return {{"uri", UriOfPath(file)}, {"range", Range(at.line - 1, from, from + unsigned(name.size()))}};
    };
    for (auto& k : job->model.kernels)
      if (json found = place(k.name, k.definedAt); !found.is_null()) return found;
    for (auto& c : job->model.controls)
      if (json found = place(c.name, c.definedAt); !found.is_null()) return found;
  }
  return nullptr;
}

json Server::CodeActions(const std::string& uri, const std::string& path, const json& params) {
  const std::string text = TextOf(path);
  json actions = json::array();
  const json& diagnostics = Field(Field(params, "context"), "diagnostics");
  if (!diagnostics.is_array()) return actions;
  for (auto& d : diagnostics) {
    if (StringField(d, "source").rfind("crossrt", 0) != 0) continue;
    const json& start = Field(Field(d, "range"), "start");
    const unsigned line = NumberField(start, "line");
    auto fix = QuickFixFor(StringField(d, "message"), text, OffsetOfPosition(text, line, NumberField(start, "character")));
    if (!fix) continue;
    const unsigned character = CharacterOfColumn(text, fix->line, fix->column);
    json edits = json::array();
    edits.push_back({{"range", Range(fix->line, character, character)}, {"newText", fix->insert}});
    json changes = json::object();
    changes[uri] = edits;
    json action = {{"title", fix->title}, {"kind", "quickfix"}, {"isPreferred", true}};
    action["diagnostics"] = json::array({d});
    action["edit"] = {{"changes", changes}};
    actions.push_back(action);
  }
  return actions;
}

json Server::ShowGenerated(const json& params) {
  if (StringField(params, "command") != "crossrt.showGenerated") throw std::runtime_error("unknown command '" + StringField(params, "command") + "'");
  const json& arguments = Field(params, "arguments");
  const json& target = arguments.is_array() && !arguments.empty() ? arguments[0] : json();
  const std::string uri = StringField(target, "uri");
  const unsigned line = NumberField(target, "line");
  if (PathOfUri(uri).empty()) throw std::runtime_error("crossrt.showGenerated takes {uri, line}");
  if (m_showDocument) {
    const unsigned at = line ? line - 1 : 0;
    Queue({{"jsonrpc", "2.0"}, {"id", "crossrt-" + std::to_string(m_nextRequest++)}, {"method", "window/showDocument"},
           {"params", {{"uri", uri}, {"takeFocus", true}, {"selection", Range(at, 0, 0)}}}});
  }
  return {{"uri", uri}, {"line", line}};
}

}  // namespace

int RunLanguageServer(const ServerOptions& options, int in, int out) {
  Server server(options, in, out);
  return server.Run();
}

}  // namespace crossrt::lsp
