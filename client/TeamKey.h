// The team key that authenticates remote cache entries (docs/remote-cache.md, "Trust").
//
// A fetched entry is generated C++ and SPIR-V that the build compiles into the user's program, so
// with a key every entry carries an HMAC-SHA256 (OpenSSL) over its storage key, its kind and its
// bytes, and an entry that does not verify is never used. The key comes from the environment
// (CROSSRT_REMOTE_KEY, the key itself) or from a file (CROSSRT_REMOTE_KEY_FILE, or the path that
// the CMake variable of that name passes as --remote-key-file); never from the command line, where
// `ps` and build logs would show it. Messages name a key by its id, a hash that reveals nothing of it.
#pragma once
#include <optional>
#include <string>

namespace crossrt::client {

class TeamKey {
public:
  // The key that the environment or `keyFile` names: std::nullopt when none is configured, and
  // std::nullopt with a message in `error` when one is configured but unusable (unreadable, or
  // shorter than kMinimumLength characters).
  static std::optional<TeamKey> Load(const std::string& keyFile, std::string& error);
  explicit TeamKey(std::string secret);

  static constexpr size_t kMinimumLength = 32;  // characters: `openssl rand -hex 32` gives 64

  // 16 hex digits of SHA-256 over a fixed prefix and the key: safe to print and to store.
  const std::string& Id() const { return m_id; }
  // The signature of an entry: "hmac-sha256:<id>:<64 hex digits>".
  std::string Sign(const std::string& kind, const std::string& storageKey, const std::string& body) const;
  // "" when `signature` is this key's signature of the entry; otherwise why not, in words.
  std::string Verify(const std::string& signature, const std::string& kind, const std::string& storageKey,
                     const std::string& body) const;

private:
  std::string Mac(const std::string& kind, const std::string& storageKey, const std::string& body) const;
  std::string m_secret, m_id;
};

}  // namespace crossrt::client
