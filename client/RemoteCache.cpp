// The remote translation cache (RemoteCache.h says what it stores and why): keys, entries, and the
// lookup and upload over the configured storages.
#include "RemoteCache.h"

#include "DaemonClient.h"
#include "InProcess.h"
#include "Protocol.h"
#include "RemoteRejections.h"

#include <xxhash.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace crossrt::client {

namespace {

constexpr const char* kFormat = "CROSSRT-REMOTE-CACHE 1";  // the first line of every entry, with its kind
constexpr size_t kSetsPerManifest = 8;                     // input sets a manifest remembers, newest first
constexpr int kWarningWindowSeconds = 600;                 // one warning per build: none within this of the last

std::string Hex128(const std::string& data, uint64_t seed = 0) {
  const XXH128_hash_t h = XXH3_128bits_withSeed(data.data(), data.size(), seed);
  char buf[40];
  std::snprintf(buf, sizeof buf, "%016llx%016llx", (unsigned long long)h.high64, (unsigned long long)h.low64);
  return buf;
}
// 64 hex digits: the key length the Bazel remote cache's layout takes.
std::string Key(const std::string& text) { return Hex128(text, 0) + Hex128(text, 1); }

std::string ReadFile(const std::string& path, bool& ok) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  ok = bool(in);
  return os.str();
}

// An entry's body: fields, each "<length>\n<bytes>".
std::string Field(const std::string& s) { return std::to_string(s.size()) + "\n" + s; }
std::string Field(size_t n) { return Field(std::to_string(n)); }
class Fields {
public:
  explicit Fields(const std::string& body) : m_body(body) {}
  bool Next(std::string& out) {
    const size_t eol = m_body.find('\n', m_at);
    if (eol == std::string::npos || eol == m_at || eol - m_at > 12) return false;
    size_t length = 0;
    for (size_t i = m_at; i < eol; ++i) {
      if (m_body[i] < '0' || m_body[i] > '9') return false;
      length = length * 10 + size_t(m_body[i] - '0');
    }
    if (length > m_body.size() - eol - 1) return false;
    out = m_body.substr(eol + 1, length);
    m_at = eol + 1 + length;
    return true;
  }
  bool Next(size_t& n) {
    std::string text;
    if (!Next(text) || text.empty() || text.size() > 9 || text.find_first_not_of("0123456789") != std::string::npos) return false;
    n = std::stoul(text);
    return true;
  }
  bool AtEnd() const { return m_at == m_body.size(); }

private:
  const std::string& m_body;
  size_t m_at = 0;
};

// "<format> <kind> <checksum>[ <signature>]\n<body>"; the signature only with a team key.
std::string Encode(const std::string& kind, const std::string& storageKey, const std::string& body, const TeamKey* key) {
  std::string header = std::string(kFormat) + " " + kind + " " + Hex128(body);
  if (key) header += " " + key->Sign(kind, storageKey, body);
  return header + "\n" + body;
}

enum class Entry { Unusable, Rejected, Usable };
// The body of an entry of that kind stored under `storageKey`. Unusable: another format or kind,
// truncated, or its checksum fails (replaced by the next upload, silently). Rejected: with a team
// key, the entry's signature does not verify; `why` says how.
Entry Decode(const std::string& entry, const std::string& kind, const std::string& storageKey, const TeamKey* key,
             std::string& body, std::string& why) {
  const std::string header = std::string(kFormat) + " " + kind + " ";
  const size_t eol = entry.find('\n');
  if (entry.compare(0, header.size(), header) != 0 || eol == std::string::npos) return Entry::Unusable;
  const std::string rest = entry.substr(header.size(), eol - header.size());
  const size_t space = rest.find(' ');
  body = entry.substr(eol + 1);
  if (rest.substr(0, space) != Hex128(body)) return Entry::Unusable;
  if (!key) return Entry::Usable;  // without a key, a signature is not checked (docs: "Trust")
  why = key->Verify(space == std::string::npos ? "" : rest.substr(space + 1), kind, storageKey, body);
  return why.empty() ? Entry::Usable : Entry::Rejected;
}

// The input sets of a manifest: each its result's key and its (portable path, content hash) pairs.
struct InputSet {
  std::string result;
  std::vector<std::pair<std::string, std::string>> inputs;
};
bool ParseManifest(const std::string& body, const std::string& identity, std::vector<InputSet>& sets) {
  Fields f(body);
  std::string id;
  size_t count = 0;
  if (!f.Next(id) || id != identity || !f.Next(count)) return false;
  for (size_t i = 0; i < count; ++i) {
    InputSet set;
    size_t n = 0;
    if (!f.Next(set.result) || !f.Next(n)) return false;
    set.inputs.resize(n);
    for (auto& [path, hash] : set.inputs)
      if (!f.Next(path) || !f.Next(hash)) return false;
    sets.push_back(std::move(set));
  }
  return f.AtEnd();
}

// The translator's identity across machines: its version and a hash of the daemon's bytes (the
// engine is linked into it) and of the engine module's (which --no-daemon loads: a build may
// rebuild it alone), remembered in the build tree by the files' sizes, times and inodes.
std::string TranslatorContentIdentity(const std::string& buildDir) {
  const std::string executable = DaemonExecutable(), module = EnginePath();
  const std::string local = protocol::TranslatorIdentity(executable) + "+" + protocol::TranslatorIdentity(module);
  const std::string memo = buildDir.empty() ? "" : buildDir + "/.crossrt-translator-identity";
  if (!memo.empty()) {
    std::ifstream in(memo);
    std::string statIdentity, contentIdentity;
    if (in >> statIdentity >> contentIdentity && statIdentity == local) return contentIdentity;
  }
  bool ok = false, moduleOk = false;
  const std::string bytes = ReadFile(executable, ok), moduleBytes = module.empty() ? "" : ReadFile(module, moduleOk);
  const std::string identity = std::string(engine::kTranslatorVersion) + "/" + (ok ? Hex128(bytes) : "unknown") + "+" +
                               (moduleOk ? Hex128(moduleBytes) : "none");
  if (!memo.empty() && ok) {
    const std::string tmp = memo + "." + std::to_string(::getpid());
    std::ofstream(tmp) << local << " " << identity << "\n";
    std::error_code ec;
    std::filesystem::rename(tmp, memo, ec);
  }
  return identity;
}

}  // namespace

RemoteCache::RemoteCache(const std::string& storages, const std::string& sourceRoot, const std::string& buildDir,
                         const std::string& keyFile)
    : m_buildDir(buildDir) {
  std::vector<std::string> errors;
  m_storages = ParseRemoteStorages(storages, errors);
  for (auto& e : errors) std::cerr << "crossrt: warning: CROSSRT_REMOTE_STORAGE: " << e << "; left out\n";
  if (m_storages.empty()) return;
  std::string keyError;
  m_key = TeamKey::Load(keyFile, keyError);
  if (!keyError.empty()) {
    // A key was meant to protect this build: going on without one would trust unsigned entries.
    std::cerr << "crossrt: warning: remote cache key: " << keyError << "; the remote cache is off for this translation\n";
    m_storages.clear();
    return;
  }
  auto add = [&](const std::string& folder, const char* placeholder) {
    if (folder.empty()) return;
    std::error_code ec;
    std::string canonical = std::filesystem::weakly_canonical(folder, ec).string();
    while (canonical.size() > 1 && canonical.back() == '/') canonical.pop_back();
    if (!ec && canonical.size() > 1) m_folders.emplace_back(canonical, placeholder);
  };
  add(buildDir, "@CROSSRT_BUILD_DIR@");
  add(sourceRoot, "@CROSSRT_SOURCE_ROOT@");
  // The longer first: a build tree inside the source tree is the build tree.
  std::sort(m_folders.begin(), m_folders.end(), [](auto& a, auto& b) { return a.first.size() > b.first.size(); });
  m_identity = TranslatorContentIdentity(buildDir);
}

RemoteCache::~RemoteCache() = default;

std::string RemoteCache::Portable(const std::string& text) const {
  std::string out = text;
  for (auto& [folder, placeholder] : m_folders) {
    for (size_t at = 0; (at = out.find(folder, at)) != std::string::npos;) {
      const size_t end = at + folder.size();
      // Only the whole folder: /a/src, not /a/src2.
      if (end == out.size() || out[end] == '/' || out[end] == '"' || out[end] == '>' || out[end] == '\n' || out[end] == ' ') {
        out.replace(at, folder.size(), placeholder);
        at += std::string(placeholder).size();
      } else {
        at = end;
      }
    }
  }
  return out;
}

std::string RemoteCache::Local(const std::string& text) const {
  std::string out = text;
  for (auto& [folder, placeholder] : m_folders)
    for (size_t at = 0; (at = out.find(placeholder, at)) != std::string::npos; at += folder.size()) out.replace(at, std::string(placeholder).size(), folder);
  return out;
}

std::string RemoteCache::ManifestKey(const engine::TranslateRequest& r) const {
  std::string text = "manifest\n" + m_identity + "\n" + r.className + "\n" + engine::BackendName(r.backend);
  text += "\ntemplates " + Portable(r.templateDir) + "\nout " + Portable(r.outputDir);
  for (auto& s : r.sources) text += "\nsrc " + Portable(s);
  for (auto& a : r.compileArgs) text += "\narg " + Portable(a);
  for (auto& c : r.compositions) text += "\ncompose " + c;
  text += "\nvirtual-level " + std::to_string(r.virtualLevel);
  text += std::string("\nexecution-mode ") + (r.megakernel ? "megakernel" : "wavefront");
  text += "\nname " + r.generatedName;
  return Key(text);
}

std::string RemoteCache::ContentHash(const std::string& path) {
  if (auto it = m_hashes.find(path); it != m_hashes.end()) return it->second;
  bool ok = false;
  const std::string bytes = ReadFile(path, ok);
  return m_hashes[path] = ok ? Hex128(bytes) : "";
}

void RemoteCache::Warn(const RemoteStorage& storage, const std::string& what, const std::string& error) {
  // One warning per build: the first process to fail leaves a mark in the build tree that the
  // others of the same build see.
  if (!m_buildDir.empty()) {
    const std::string mark = m_buildDir + "/.crossrt-remote-warning";
    struct stat st {};
    if (stat(mark.c_str(), &st) == 0 && std::time(nullptr) - st.st_mtime < kWarningWindowSeconds) return;
    std::ofstream(mark) << storage.Url() << ": " << error << "\n";
  }
  std::cerr << "crossrt: warning: remote storage " << storage.Url() << ": " << what << " failed (" << error
            << "); translating locally. Further failures in this build are not reported.\n";
}

void RemoteCache::Reject(const RemoteStorage& storage, const engine::TranslateRequest& request, const std::string& kind,
                         const std::string& why) {
  // Every rejection is reported: it is an entry someone wrote without this build's key.
  const std::string what = "the " + kind + " entry for class '" + request.className + "' (" +
                           engine::BackendName(request.backend) + ")";
  std::cerr << "crossrt: warning: remote storage " << storage.Url() << ": rejected " << what << ": " << why
            << "; this build takes only entries signed with key " << m_key->Id() << ". Translating locally.\n";
  RecordRejection(m_buildDir, storage.Url(), what + ", key " + m_key->Id(), why);
}

bool RemoteCache::Fetch(const engine::TranslateRequest& request, engine::TranslateResult& result) {
  const std::string manifestKey = ManifestKey(request);
  for (auto& storage : m_storages) {
    std::string error, body;
    std::optional<std::string> manifest = storage->Get(manifestKey, error);
    if (!error.empty()) {
      Warn(*storage, "reading", error);
      continue;
    }
    std::vector<InputSet> sets;
    if (!manifest) continue;
    std::string why;
    const Entry decoded = Decode(*manifest, "manifest", manifestKey, Signer(), body, why);
    if (decoded == Entry::Rejected) Reject(*storage, request, "manifest", why);
    if (decoded != Entry::Usable || !ParseManifest(body, m_identity, sets)) continue;
    for (const InputSet& set : sets) {
      bool same = true;
      for (auto& [path, hash] : set.inputs) same = same && ContentHash(Local(path)) == hash;
      if (!same) continue;
      std::optional<std::string> entry = storage->Get(set.result, error);
      if (!error.empty()) {
        Warn(*storage, "reading", error);
        break;
      }
      if (!entry) break;  // gone: translated and stored again
      const Entry decodedResult = Decode(*entry, "result", set.result, Signer(), body, why);
      if (decodedResult == Entry::Rejected) Reject(*storage, request, "result", why);
      if (decodedResult != Entry::Usable) break;  // corrupt or rejected: translated, and replaced by the upload
      Fields f(body);
      std::string identity, diagnostics;
      size_t inputs = 0, files = 0;
      engine::TranslateResult fetched;
      bool ok = f.Next(identity) && identity == m_identity && f.Next(diagnostics) && f.Next(inputs);
      for (size_t i = 0; ok && i < inputs; ++i) {
        std::string path;
        ok = f.Next(path);
        fetched.inputs.push_back(Local(path));
      }
      ok = ok && f.Next(files);
      for (size_t i = 0; ok && i < files; ++i) {
        std::string name, contents;
        ok = f.Next(name) && f.Next(contents) && !name.empty() && name[0] != '/' && name.find("..") == std::string::npos;
        fetched.files[name] = Local(contents);
      }
      if (!ok || !f.AtEnd() || fetched.files.empty()) break;
      fetched.ok = true;
      fetched.diagnostics = Local(diagnostics);
      result = std::move(fetched);
      return true;
    }
  }
  return false;
}

void RemoteCache::Store(const engine::TranslateRequest& request, const engine::TranslateResult& result) {
  const std::string manifestKey = ManifestKey(request);
  InputSet set;
  std::string keyText = "result\n" + manifestKey;
  for (auto& path : result.inputs) {
    const std::string hash = ContentHash(path);
    if (hash.empty()) return;  // an input that cannot be read cannot be checked by another build
    set.inputs.emplace_back(Portable(path), hash);
    keyText += "\n" + set.inputs.back().first + " " + hash;
  }
  set.result = Key(keyText);
  std::string body = Field(m_identity) + Field(Portable(result.diagnostics)) + Field(result.inputs.size());
  for (auto& [path, hash] : set.inputs) body += Field(path);
  body += Field(result.files.size());
  for (auto& [name, contents] : result.files) body += Field(name) + Field(Portable(contents));
  const std::string entry = Encode("result", set.result, body, Signer());

  for (auto& storage : m_storages) {
    if (storage->Attributes().readOnly) continue;
    std::string error;
    if (!storage->Put(set.result, entry, error)) {
      Warn(*storage, "writing", error);
      continue;
    }
    // The manifest: this input set first, then the others it held (a corrupt one is replaced).
    std::vector<InputSet> sets{set}, old;
    std::string oldBody, why;
    std::optional<std::string> manifest = storage->Get(manifestKey, error);
    if (manifest && Decode(*manifest, "manifest", manifestKey, Signer(), oldBody, why) == Entry::Usable &&
        ParseManifest(oldBody, m_identity, old))
      for (auto& s : old)
        if (s.result != set.result && sets.size() < kSetsPerManifest) sets.push_back(s);
    std::string manifestBody = Field(m_identity) + Field(sets.size());
    for (auto& s : sets) {
      manifestBody += Field(s.result) + Field(s.inputs.size());
      for (auto& [path, hash] : s.inputs) manifestBody += Field(path) + Field(hash);
    }
    error.clear();
    if (!storage->Put(manifestKey, Encode("manifest", manifestKey, manifestBody, Signer()), error)) Warn(*storage, "writing", error);
  }
}

}  // namespace crossrt::client
