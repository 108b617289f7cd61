// Translations shared through remote storages (RemoteStorage.h), as ccache shares compiler outputs.
//
// A translation is a pure function of its options and its inputs' contents, so it is stored in two
// entries, as ccache's direct mode stores a compilation:
//   - a manifest, keyed by the options: the input sets (paths and content hashes) seen with them,
//     each naming its result;
//   - a result, keyed by the options and one input set: every generated file, the diagnostics and
//     the input list (for the depfile).
// Paths under the build tree and the source root are stored relative to them, so two build trees
// in different folders, or on different machines, share entries, and a fetched translation is
// byte-identical to a local one. Entries carry a format version, the translator's identity (a hash
// of its daemon's bytes) and a checksum; anything else is ignored and replaced. A storage that fails
// makes the build translate locally, with one warning per build, never an error.
//
// With a team key (TeamKey.h) every entry is signed, and an entry that is unsigned, signed with
// another key or altered is rejected: a warning names the storage and the key, the rejection is
// recorded for `crossrt daemon status` (RemoteRejections.h), and the class is translated locally.
#pragma once
#include "RemoteStorage.h"
#include "TeamKey.h"
#include "TranslateTypes.h"

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace crossrt::client {

class RemoteCache {
public:
  // `storages`: the CROSSRT_REMOTE_STORAGE list; `sourceRoot`, `buildDir`: the folders whose paths
  // entries hold relative (either may be empty); `keyFile`: the team key's file, when the build
  // names one (CROSSRT_REMOTE_KEY and CROSSRT_REMOTE_KEY_FILE win). A key that is configured but
  // unusable turns the remote cache off, with a warning.
  RemoteCache(const std::string& storages, const std::string& sourceRoot, const std::string& buildDir,
              const std::string& keyFile = "");
  ~RemoteCache();
  bool Enabled() const { return !m_storages.empty(); }

  // The translation of `request` from the first storage that has it for the inputs as they are now;
  // false when none has.
  bool Fetch(const engine::TranslateRequest& request, engine::TranslateResult& result);
  // Uploads a local translation to every storage that is not read-only.
  void Store(const engine::TranslateRequest& request, const engine::TranslateResult& result);

private:
  std::string Portable(const std::string& text) const;  // this machine's folders -> placeholders
  std::string Local(const std::string& text) const;     // placeholders -> this machine's folders
  std::string ManifestKey(const engine::TranslateRequest& request) const;
  std::string ContentHash(const std::string& path);  // "" when unreadable; remembered per path
  void Warn(const RemoteStorage& storage, const std::string& what, const std::string& error);
  void Reject(const RemoteStorage& storage, const engine::TranslateRequest& request, const std::string& kind,
              const std::string& why);
  const TeamKey* Signer() const { return m_key ? &*m_key : nullptr; }

  std::vector<std::unique_ptr<RemoteStorage>> m_storages;
  std::optional<TeamKey> m_key;
  std::vector<std::pair<std::string, std::string>> m_folders;  // folder, placeholder: longest first
  std::string m_buildDir, m_identity;
  std::map<std::string, std::string> m_hashes;
};

}  // namespace crossrt::client
