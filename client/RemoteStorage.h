// Remote storages that a team already runs, as ccache's remote storage names them: Redis
// (redis://[[user]:password@]host[:port][/db]) and HTTP (http[s]://[user:token@]host[:port]/path,
// plain GET and PUT of <url>/<key>: nginx's WebDAV module, ccache-style HTTP storages, or a Bazel
// remote cache with |layout=bazel, which stores <url>/ac/<key>). https:// always checks the server's
// certificate and host name. rediss:// (Redis over TLS) needs hiredis 1.0 with TLS, which Debian 12's
// hiredis 0.14 lacks: such a URL is refused with a message saying so. A storage only moves bytes by key;
// RemoteCache.h decides what they mean. It never throws: a failure is a message.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace crossrt::client {

struct StorageAttributes {
  bool readOnly = false;          // |read-only
  int connectTimeoutMs = 100;     // |connect-timeout=MS
  int operationTimeoutMs = 2000;  // |operation-timeout=MS
  bool bazelLayout = false;       // |layout=bazel (HTTP only)
  std::string caFile;             // |ca-file=PEM: the certificate authorities https:// trusts (default: the system's)
};

class RemoteStorage {
public:
  virtual ~RemoteStorage() = default;
  // The value stored under `key`, std::nullopt when there is none. On failure, std::nullopt and a
  // message in `error`.
  virtual std::optional<std::string> Get(const std::string& key, std::string& error) = 0;
  // Stores `value` under `key`; false and a message in `error` on failure.
  virtual bool Put(const std::string& key, const std::string& value, std::string& error) = 0;

  const std::string& Url() const { return m_printable; }  // without credentials: safe to print
  const StorageAttributes& Attributes() const { return m_attributes; }

protected:
  RemoteStorage(std::string url, StorageAttributes attributes) : m_printable(std::move(url)), m_attributes(attributes) {}

private:
  std::string m_printable;
  StorageAttributes m_attributes;
};

// "redis://host|read-only http://host/cache" -> the storages, in order. A malformed entry is a
// message in `errors` (never with its credentials) and is left out.
std::vector<std::unique_ptr<RemoteStorage>> ParseRemoteStorages(const std::string& config, std::vector<std::string>& errors);

// `url` with any user name and password replaced by "***".
std::string RedactedUrl(const std::string& url);

}  // namespace crossrt::client
