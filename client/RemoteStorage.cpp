// Redis through hiredis and HTTP through libcurl, behind RemoteStorage (RemoteStorage.h says what
// each URL means). Connections open on first use and stay open for the process; a storage that
// failed once is not asked again by the same process.
#include "RemoteStorage.h"

#include <curl/curl.h>
#include <hiredis/hiredis.h>

#include <cstdlib>
#include <mutex>
#include <sstream>

namespace crossrt::client {

namespace {

struct ParsedUrl {
  std::string scheme, user, password, host, path;
  int port = 0;
  bool hasUserInfo = false;
};

// scheme://[user[:password]@]host[:port][/path]; false when it is not of that form.
bool ParseUrl(const std::string& text, ParsedUrl& url) {
  const size_t colon = text.find("://");
  if (colon == std::string::npos || colon == 0) return false;
  url.scheme = text.substr(0, colon);
  std::string rest = text.substr(colon + 3);
  const size_t slash = rest.find('/');
  std::string authority = rest.substr(0, slash);
  url.path = slash == std::string::npos ? "" : rest.substr(slash);
  if (const size_t at = authority.rfind('@'); at != std::string::npos) {
    url.hasUserInfo = true;
    std::string userInfo = authority.substr(0, at);
    authority = authority.substr(at + 1);
    const size_t c = userInfo.find(':');
    url.user = userInfo.substr(0, c);
    if (c != std::string::npos) url.password = userInfo.substr(c + 1);
  }
  std::string host = authority, port;
  if (!host.empty() && host[0] == '[') {  // [::1]:6379
    const size_t close = host.find(']');
    if (close == std::string::npos) return false;
    port = close + 1 < host.size() && host[close + 1] == ':' ? host.substr(close + 2) : "";
    host = host.substr(1, close - 1);
  } else if (const size_t c = host.rfind(':'); c != std::string::npos) {
    port = host.substr(c + 1);
    host = host.substr(0, c);
  }
  if (host.empty()) return false;
  url.host = host;
  if (!port.empty()) {
    char* end = nullptr;
    const long p = std::strtol(port.c_str(), &end, 10);
    if (*end || p <= 0 || p > 65535) return false;
    url.port = int(p);
  }
  return true;
}

// The URL as it may be printed: no user name, no password.
std::string Printable(const ParsedUrl& url) {
  std::string text = url.scheme + "://" + (url.hasUserInfo ? "***@" : "") + url.host;
  if (url.port) text += ":" + std::to_string(url.port);
  return text + url.path;
}

// --- Redis ---------------------------------------------------------------------------------------

class RedisStorage : public RemoteStorage {
public:
  RedisStorage(const ParsedUrl& url, StorageAttributes attributes) : RemoteStorage(Printable(url), attributes), m_address(url) {}
  ~RedisStorage() override {
    if (m_context) redisFree(m_context);
  }

  std::optional<std::string> Get(const std::string& key, std::string& error) override {
    if (!Connect(error)) return std::nullopt;
    const std::string name = "crossrt:" + key;
    redisReply* reply = static_cast<redisReply*>(redisCommand(m_context, "GET %b", name.data(), name.size()));
    std::optional<std::string> value;
    if (!Check(reply, error)) return std::nullopt;
    if (reply->type == REDIS_REPLY_STRING) value = std::string(reply->str, reply->len);
    else if (reply->type != REDIS_REPLY_NIL) error = "unexpected reply to GET";
    freeReplyObject(reply);
    return value;
  }

  bool Put(const std::string& key, const std::string& value, std::string& error) override {
    if (!Connect(error)) return false;
    const std::string name = "crossrt:" + key;
    redisReply* reply = static_cast<redisReply*>(
        redisCommand(m_context, "SET %b %b", name.data(), name.size(), value.data(), value.size()));
    if (!Check(reply, error)) return false;
    freeReplyObject(reply);
    return true;
  }

private:
  static timeval Time(int ms) { return {ms / 1000, (ms % 1000) * 1000}; }

  // A reply that is an error, or none (the connection failed): false, the message in `error`.
  bool Check(redisReply* reply, std::string& error) {
    if (!reply) {
      error = m_context->errstr[0] ? m_context->errstr : "no reply";
      m_failed = error;
      return false;
    }
    if (reply->type == REDIS_REPLY_ERROR) {
      error = std::string("server error: ") + std::string(reply->str, reply->len);
      freeReplyObject(reply);
      return false;
    }
    return true;
  }

  bool Connect(std::string& error) {
    if (!m_failed.empty()) {
      error = m_failed;
      return false;
    }
    if (m_context) return true;
    m_context = redisConnectWithTimeout(m_address.host.c_str(), m_address.port ? m_address.port : 6379, Time(Attributes().connectTimeoutMs));
    if (!m_context || m_context->err) {
      m_failed = m_context ? std::string("cannot connect: ") + m_context->errstr : "cannot allocate a connection";
      error = m_failed;
      return false;
    }
    redisSetTimeout(m_context, Time(Attributes().operationTimeoutMs));
    if (!m_address.password.empty()) {
      redisReply* reply = static_cast<redisReply*>(
          m_address.user.empty() ? redisCommand(m_context, "AUTH %s", m_address.password.c_str())
                             : redisCommand(m_context, "AUTH %s %s", m_address.user.c_str(), m_address.password.c_str()));
      if (!Check(reply, error)) return m_failed = "authentication failed", error = m_failed, false;
      freeReplyObject(reply);
    }
    if (m_address.path.size() > 1) {  // /db
      redisReply* reply = static_cast<redisReply*>(redisCommand(m_context, "SELECT %s", m_address.path.c_str() + 1));
      if (!Check(reply, error)) return m_failed = error, false;
      freeReplyObject(reply);
    }
    return true;
  }

  ParsedUrl m_address;
  redisContext* m_context = nullptr;
  std::string m_failed;  // why the connection failed, once it did
};

// --- HTTP ----------------------------------------------------------------------------------------

size_t Append(char* data, size_t size, size_t count, void* out) {
  static_cast<std::string*>(out)->append(data, size * count);
  return size * count;
}

struct Upload {
  const std::string* data;
  size_t at = 0;
};
size_t Read(char* buffer, size_t size, size_t count, void* in) {
  auto* upload = static_cast<Upload*>(in);
  const size_t n = std::min(size * count, upload->data->size() - upload->at);
  upload->data->copy(buffer, n, upload->at);
  upload->at += n;
  return n;
}

class HttpStorage : public RemoteStorage {
public:
  HttpStorage(const std::string& url, const ParsedUrl& parsed, StorageAttributes attributes)
      : RemoteStorage(Printable(parsed), attributes), m_address(url), m_userInfo(parsed.user + ":" + parsed.password) {
    static std::once_flag init;
    std::call_once(init, [] { curl_global_init(CURL_GLOBAL_DEFAULT); });
    while (!m_address.empty() && m_address.back() == '/') m_address.pop_back();
  }
  ~HttpStorage() override {
    if (m_curl) curl_easy_cleanup(m_curl);
    if (m_headers) curl_slist_free_all(m_headers);
  }

  std::optional<std::string> Get(const std::string& key, std::string& error) override {
    std::string body;
    long code = 0;
    if (!Perform(key, nullptr, body, code, error)) return std::nullopt;
    if (code == 200) return body;
    if (code != 404) error = "HTTP " + std::to_string(code) + " for GET";
    return std::nullopt;
  }

  bool Put(const std::string& key, const std::string& value, std::string& error) override {
    std::string body;
    long code = 0;
    if (!Perform(key, &value, body, code, error)) return false;
    if (code >= 200 && code < 300) return true;
    error = "HTTP " + std::to_string(code) + " for PUT";
    return false;
  }

private:
  bool Perform(const std::string& key, const std::string* upload, std::string& body, long& code, std::string& error) {
    if (!m_failed.empty()) {
      error = m_failed;
      return false;
    }
    if (!m_curl) {
      m_curl = curl_easy_init();
      if (!m_curl) return error = m_failed = "cannot initialise libcurl", false;
      m_headers = curl_slist_append(nullptr, "Expect:");  // no 100-continue round trip before a PUT
    }
    curl_easy_reset(m_curl);
    const std::string url = m_address + (Attributes().bazelLayout ? "/ac/" : "/") + key;
    char message[CURL_ERROR_SIZE] = "";
    Upload source{upload};
    curl_easy_setopt(m_curl, CURLOPT_URL, url.c_str());
    curl_easy_setopt(m_curl, CURLOPT_NOSIGNAL, 1L);
    curl_easy_setopt(m_curl, CURLOPT_CONNECTTIMEOUT_MS, long(Attributes().connectTimeoutMs));
    curl_easy_setopt(m_curl, CURLOPT_TIMEOUT_MS, long(Attributes().operationTimeoutMs));
    curl_easy_setopt(m_curl, CURLOPT_ERRORBUFFER, message);
    curl_easy_setopt(m_curl, CURLOPT_WRITEFUNCTION, Append);
    curl_easy_setopt(m_curl, CURLOPT_WRITEDATA, &body);
    curl_easy_setopt(m_curl, CURLOPT_HTTPHEADER, m_headers);
    // Certificates and host names are checked (libcurl's defaults, set here so that no
    // environment turns them off); |ca-file names the authorities to trust instead of the system's.
    curl_easy_setopt(m_curl, CURLOPT_SSL_VERIFYPEER, 1L);
    curl_easy_setopt(m_curl, CURLOPT_SSL_VERIFYHOST, 2L);
    if (!Attributes().caFile.empty()) curl_easy_setopt(m_curl, CURLOPT_CAINFO, Attributes().caFile.c_str());
    if (upload) {
      curl_easy_setopt(m_curl, CURLOPT_UPLOAD, 1L);
      curl_easy_setopt(m_curl, CURLOPT_READFUNCTION, Read);
      curl_easy_setopt(m_curl, CURLOPT_READDATA, &source);
      curl_easy_setopt(m_curl, CURLOPT_INFILESIZE_LARGE, curl_off_t(upload->size()));
    }
    const CURLcode result = curl_easy_perform(m_curl);
    if (result != CURLE_OK) {
      error = Scrubbed(message[0] ? message : curl_easy_strerror(result));
      if (result == CURLE_COULDNT_CONNECT || result == CURLE_COULDNT_RESOLVE_HOST || result == CURLE_OPERATION_TIMEDOUT)
        m_failed = error;
      return false;
    }
    curl_easy_getinfo(m_curl, CURLINFO_RESPONSE_CODE, &code);
    return true;
  }

  // libcurl's message without the URL's credentials, should it quote them.
  std::string Scrubbed(std::string text) const {
    for (const std::string& secret : {m_userInfo, m_userInfo.substr(m_userInfo.find(':') + 1)})
      if (secret.size() > 1)
        for (size_t at; (at = text.find(secret)) != std::string::npos;) text.replace(at, secret.size(), "***");
    return text;
  }

  std::string m_address;       // with credentials, for libcurl only
  std::string m_userInfo;  // user:password
  CURL* m_curl = nullptr;
  curl_slist* m_headers = nullptr;
  std::string m_failed;
};

// "read-only", "connect-timeout=100", ... into `attributes`; false on an unknown one.
bool ParseAttribute(const std::string& text, StorageAttributes& attributes, std::string& error) {
  const size_t eq = text.find('=');
  const std::string name = text.substr(0, eq), value = eq == std::string::npos ? "" : text.substr(eq + 1);
  auto number = [&](int& out) {
    char* end = nullptr;
    const long v = std::strtol(value.c_str(), &end, 10);
    if (value.empty() || *end || v <= 0) return error = "attribute '" + name + "' takes a number of milliseconds", false;
    out = int(v);
    return true;
  };
  if (name == "read-only") return attributes.readOnly = value.empty() || value == "true", true;
  if (name == "connect-timeout") return number(attributes.connectTimeoutMs);
  if (name == "operation-timeout") return number(attributes.operationTimeoutMs);
  if (name == "ca-file") {
    if (value.empty()) return error = "attribute 'ca-file' takes the path of a PEM file", false;
    attributes.caFile = value;
    return true;
  }
  if (name == "layout") {
    if (value != "flat" && value != "bazel") return error = "layout is flat or bazel, not '" + value + "'", false;
    attributes.bazelLayout = value == "bazel";
    return true;
  }
  error = "unknown attribute '" + name + "' (known: read-only, connect-timeout, operation-timeout, layout, ca-file)";
  return false;
}

}  // namespace

std::string RedactedUrl(const std::string& text) {
  ParsedUrl url;
  if (!ParseUrl(text, url)) {  // not a URL: hide anything before an '@'
    const size_t at = text.rfind('@');
    return at == std::string::npos ? text : "***" + text.substr(at);
  }
  return Printable(url);
}

std::vector<std::unique_ptr<RemoteStorage>> ParseRemoteStorages(const std::string& config, std::vector<std::string>& errors) {
  std::vector<std::unique_ptr<RemoteStorage>> storages;
  std::istringstream words(config);
  for (std::string word; words >> word;) {
    std::vector<std::string> parts;
    for (size_t start = 0;;) {
      const size_t bar = word.find('|', start);
      parts.push_back(word.substr(start, bar == std::string::npos ? std::string::npos : bar - start));
      if (bar == std::string::npos) break;
      start = bar + 1;
    }
    const std::string shown = RedactedUrl(parts[0]);
    ParsedUrl url;
    if (!ParseUrl(parts[0], url)) {
      errors.push_back("'" + shown + "' is not a URL (redis://host[:port] or http[s]://host[:port]/path)");
      continue;
    }
    StorageAttributes attributes;
    std::string error;
    bool ok = true;
    for (size_t i = 1; i < parts.size() && ok; ++i) ok = ParseAttribute(parts[i], attributes, error);
    if (!ok) {
      errors.push_back(shown + ": " + error);
      continue;
    }
    if (url.scheme == "redis") storages.push_back(std::make_unique<RedisStorage>(url, attributes));
    else if (url.scheme == "http" || url.scheme == "https") storages.push_back(std::make_unique<HttpStorage>(parts[0], url, attributes));
    else if (url.scheme == "rediss")
      errors.push_back(shown + ": Redis over TLS needs hiredis 1.0 with TLS, and this crossrt was built with hiredis " +
                       std::to_string(HIREDIS_MAJOR) + "." + std::to_string(HIREDIS_MINOR) +
                       ", which has none: use https://, or reach the server through a TLS tunnel (stunnel) with redis://");
    else errors.push_back(shown + ": unknown scheme '" + url.scheme + "' (redis, http or https)");
  }
  return storages;
}

}  // namespace crossrt::client
