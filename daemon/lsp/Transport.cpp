// Content-Length framing over file descriptors (Transport.h).
#include "Transport.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <unistd.h>

namespace crossrt::lsp {

bool Transport::Fill() {
  if (m_pos > 0 && m_pos == m_buffer.size()) {
    m_buffer.clear();
    m_pos = 0;
  }
  if (m_beforeWaiting) m_beforeWaiting();
  char chunk[65536];
  for (;;) {
    ssize_t n = read(m_in, chunk, sizeof chunk);
    if (n > 0) {
      m_buffer.append(chunk, size_t(n));
      return true;
    }
    if (n < 0 && errno == EINTR) continue;
    return false;
  }
}

bool Transport::ReadLine(std::string& line) {
  for (;;) {
    size_t end = m_buffer.find('\n', m_pos);
    if (end != std::string::npos) {
      line = m_buffer.substr(m_pos, end - m_pos);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      m_pos = end + 1;
      return true;
    }
    if (m_buffer.size() - m_pos > 8192) {  // no header line is this long: drop it
      m_pos = m_buffer.size();
      line = std::string(8193, '?');
      return true;
    }
    if (!Fill()) return false;
  }
}

ReadStatus Transport::Read(std::string& body) {
  long long length = -1;
  std::string problem;
  std::string line;
  bool sawHeader = false;
  for (;;) {
    if (!ReadLine(line)) return ReadStatus::Closed;
    if (line.empty()) {
      if (sawHeader) break;
      continue;  // blank lines between messages
    }
    sawHeader = true;
    const size_t colon = line.find(':');
    if (colon == std::string::npos) {
      problem = "a header line without ':'";
      continue;
    }
    std::string name = line.substr(0, colon), value = line.substr(colon + 1);
    for (auto& c : name) c = char(std::tolower((unsigned char)c));
    if (name != "content-length") continue;  // Content-Type and anything else: not needed
    char* end = nullptr;
    while (!value.empty() && value.front() == ' ') value.erase(0, 1);
    length = std::strtoll(value.c_str(), &end, 10);
    if (value.empty() || *end != '\0' || length < 0) {
      problem = "Content-Length '" + value + "' is not a length";
      length = -1;
    }
  }
  if (length < 0) {
    body = problem.empty() ? "a message without Content-Length" : problem;
    return ReadStatus::Malformed;
  }
  const bool tooLarge = size_t(length) > kMaxMessageBytes;
  if (!tooLarge) body.clear();
  size_t left = size_t(length);
  while (left > 0) {
    if (m_pos == m_buffer.size() && !Fill()) return ReadStatus::Closed;
    const size_t take = std::min(left, m_buffer.size() - m_pos);
    if (!tooLarge) body.append(m_buffer, m_pos, take);
    m_pos += take;
    left -= take;
  }
  if (tooLarge) {
    body = "a message of " + std::to_string(length) + " bytes (at most " + std::to_string(kMaxMessageBytes) + ")";
    return ReadStatus::Malformed;
  }
  return ReadStatus::Message;
}

bool Transport::Write(const nlohmann::json& message) {
  const std::string body = message.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  const std::string data = "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
  std::lock_guard<std::mutex> guard(m_writeMutex);
  size_t done = 0;
  while (done < data.size()) {
    ssize_t n = write(m_out, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}

}  // namespace crossrt::lsp
