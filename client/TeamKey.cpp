// The team key (TeamKey.h): where it comes from, its id, and HMAC-SHA256 signatures through
// OpenSSL's EVP_MAC interface.
#include "TeamKey.h"

#include <openssl/core_names.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/params.h>
#include <openssl/sha.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace crossrt::client {

namespace {

constexpr const char* kIdPrefix = "CROSSRT-REMOTE-KEY-ID\n";
constexpr const char* kMacPrefix = "CROSSRT-REMOTE-CACHE 1\n";  // the entry format the signature belongs to
constexpr const char* kScheme = "hmac-sha256";

std::string Hex(const unsigned char* bytes, size_t n) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (size_t i = 0; i < n; ++i) out += {digits[bytes[i] >> 4], digits[bytes[i] & 15]};
  return out;
}

std::string Trimmed(std::string text) {
  const char* space = " \t\r\n";
  text.erase(0, text.find_first_not_of(space) == std::string::npos ? text.size() : text.find_first_not_of(space));
  text.erase(text.find_last_not_of(space) + 1);
  return text;
}

}  // namespace

std::optional<TeamKey> TeamKey::Load(const std::string& keyFileOption, std::string& error) {
  std::string secret, origin;
  const char* fromEnvironment = std::getenv("CROSSRT_REMOTE_KEY");
  const char* fileFromEnvironment = std::getenv("CROSSRT_REMOTE_KEY_FILE");
  if (fromEnvironment && *fromEnvironment) {
    secret = Trimmed(fromEnvironment);
    origin = "CROSSRT_REMOTE_KEY";
  } else {
    const std::string file = fileFromEnvironment && *fileFromEnvironment ? fileFromEnvironment : keyFileOption;
    if (file.empty()) return std::nullopt;
    origin = "the key file '" + file + "'";
    std::ifstream in(file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in) {
      error = origin + " cannot be read";
      return std::nullopt;
    }
    secret = Trimmed(text.str());
  }
  if (secret.size() < kMinimumLength) {
    error = origin + " holds " + std::to_string(secret.size()) + " characters; a key needs at least " +
            std::to_string(kMinimumLength) + " (make one with `openssl rand -hex 32`)";
    return std::nullopt;
  }
  return TeamKey(std::move(secret));
}

TeamKey::TeamKey(std::string secret) : m_secret(std::move(secret)) {
  const std::string text = kIdPrefix + m_secret;
  unsigned char digest[SHA256_DIGEST_LENGTH];
  SHA256(reinterpret_cast<const unsigned char*>(text.data()), text.size(), digest);
  m_id = Hex(digest, 8);
}

std::string TeamKey::Mac(const std::string& kind, const std::string& storageKey, const std::string& body) const {
  // The storage key is signed too: a valid entry moved under another key (another class, other
  // inputs) does not verify there.
  const std::string head = kMacPrefix + kind + "\n" + storageKey + "\n";
  EVP_MAC* mac = EVP_MAC_fetch(nullptr, "HMAC", nullptr);
  EVP_MAC_CTX* context = mac ? EVP_MAC_CTX_new(mac) : nullptr;
  char digestName[] = "SHA256";
  const OSSL_PARAM params[] = {OSSL_PARAM_construct_utf8_string(OSSL_MAC_PARAM_DIGEST, digestName, 0), OSSL_PARAM_construct_end()};
  unsigned char out[EVP_MAX_MD_SIZE];
  size_t length = 0;
  const bool ok = context &&
                  EVP_MAC_init(context, reinterpret_cast<const unsigned char*>(m_secret.data()), m_secret.size(), params) &&
                  EVP_MAC_update(context, reinterpret_cast<const unsigned char*>(head.data()), head.size()) &&
                  EVP_MAC_update(context, reinterpret_cast<const unsigned char*>(body.data()), body.size()) &&
                  EVP_MAC_final(context, out, &length, sizeof out);
  EVP_MAC_CTX_free(context);
  EVP_MAC_free(mac);
  return ok ? Hex(out, length) : "";  // "" never verifies: Verify() compares against a non-empty MAC
}

std::string TeamKey::Sign(const std::string& kind, const std::string& storageKey, const std::string& body) const {
  return std::string(kScheme) + ":" + m_id + ":" + Mac(kind, storageKey, body);
}

std::string TeamKey::Verify(const std::string& signature, const std::string& kind, const std::string& storageKey,
                            const std::string& body) const {
  if (signature.empty()) return "it is not signed";
  const size_t first = signature.find(':'), second = signature.find(':', first == std::string::npos ? first : first + 1);
  if (first == std::string::npos || second == std::string::npos || signature.compare(0, first, kScheme) != 0)
    return "its signature is not of the form " + std::string(kScheme) + ":<key id>:<mac>";
  const std::string id = signature.substr(first + 1, second - first - 1), claimed = signature.substr(second + 1);
  if (id.size() != m_id.size() || id.find_first_not_of("0123456789abcdef") != std::string::npos)
    return "its signature names no key id";
  if (id != m_id) return "it is signed with another key (" + id + ")";
  const std::string expected = Mac(kind, storageKey, body);
  if (expected.empty()) return "OpenSSL could not compute its HMAC";
  if (claimed.size() != expected.size() || CRYPTO_memcmp(claimed.data(), expected.data(), expected.size()) != 0)
    return "its signature does not match its contents (altered after signing, or moved from another key)";
  return "";
}

}  // namespace crossrt::client
