// UTF-16 positions against UTF-8 text, and file URIs (Text.h).
#include "Text.h"

#include <algorithm>
#include <cctype>
#include <cstdio>

namespace crossrt::lsp {

namespace {

size_t LineStart(const std::string& text, unsigned line) {
  size_t at = 0;
  for (unsigned l = 0; l < line; ++l) {
    size_t next = text.find('\n', at);
    if (next == std::string::npos) return text.size();
    at = next + 1;
  }
  return at;
}

// Bytes in the UTF-8 sequence that starts with `lead`, and UTF-16 units it takes.
void Sequence(unsigned char lead, size_t& bytes, unsigned& units) {
  bytes = lead < 0x80 ? 1 : (lead >> 5) == 0x6 ? 2 : (lead >> 4) == 0xE ? 3 : (lead >> 3) == 0x1E ? 4 : 1;
  units = bytes == 4 ? 2 : 1;
}

}  // namespace

size_t OffsetOfPosition(const std::string& text, unsigned line, unsigned character) {
  size_t at = LineStart(text, line);
  unsigned counted = 0;
  while (at < text.size() && text[at] != '\n' && counted < character) {
    size_t bytes;
    unsigned units;
    Sequence((unsigned char)text[at], bytes, units);
    at = std::min(text.size(), at + bytes);
    counted += units;
  }
  return at;
}

unsigned CharacterOfColumn(const std::string& text, unsigned line, unsigned byteColumn) {
  size_t at = LineStart(text, line), end = at + byteColumn;
  unsigned units = 0;
  while (at < end && at < text.size() && text[at] != '\n') {
    size_t bytes;
    unsigned u;
    Sequence((unsigned char)text[at], bytes, u);
    at += bytes;
    units += u;
  }
  return units + unsigned(end > at ? end - at : 0);
}

std::string LineOf(const std::string& text, unsigned line) {
  size_t at = LineStart(text, line), end = text.find('\n', at);
  return text.substr(at, end == std::string::npos ? std::string::npos : end - at);
}

std::string PathOfUri(const std::string& uri) {
  const std::string scheme = "file://";
  if (uri.compare(0, scheme.size(), scheme) != 0) return "";
  std::string path;
  for (size_t i = scheme.size(); i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit((unsigned char)uri[i + 1]) && std::isxdigit((unsigned char)uri[i + 2])) {
      path += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      path += uri[i];
    }
  }
  if (path.empty() || path[0] != '/' || path.find('\0') != std::string::npos) return "";  // file://host/... is not ours
  return path;
}

std::string UriOfPath(const std::string& path) {
  std::string uri = "file://";
  for (unsigned char c : path) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '_' || c == '.' || c == '~') uri += char(c);
    else {
      char hex[4];
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      uri += hex;
    }
  }
  return uri;
}

}  // namespace crossrt::lsp
