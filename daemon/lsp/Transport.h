// The Language Server Protocol's base layer: messages framed by a Content-Length header, read from
// one file descriptor and written to another (stdin and stdout).
//
// A reader that meets a malformed header block (no length, a length that is not a number, or one
// over kMaxMessageBytes) skips it and says so; it never trusts the length with memory. Writes are
// whole messages under a lock, so that two threads never interleave their bytes.
#pragma once
#include <nlohmann/json.hpp>

#include <functional>
#include <mutex>
#include <string>

namespace crossrt::lsp {

constexpr size_t kMaxMessageBytes = 64u << 20;

enum class ReadStatus { Message, Malformed, Closed };

class Transport {
public:
  Transport(int in, int out) : m_in(in), m_out(out) {}
  // The next message's body. Malformed: `body` holds why, and the stream goes on after it.
  ReadStatus Read(std::string& body);
  // False when the peer is gone.
  bool Write(const nlohmann::json& message);
  // Called each time the reader is about to wait for more input: every message already received
  // has been read by then.
  void BeforeWaiting(std::function<void()> hook) { m_beforeWaiting = std::move(hook); }

private:
  bool Fill();                       // more bytes into m_buffer; false at end of input
  bool ReadLine(std::string& line);  // a header line without its CRLF
  int m_in, m_out;
  std::string m_buffer;
  size_t m_pos = 0;
  std::mutex m_writeMutex;
  std::function<void()> m_beforeWaiting;
};

}  // namespace crossrt::lsp
