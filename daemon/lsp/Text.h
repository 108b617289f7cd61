// Positions as the Language Server Protocol counts them (0-based lines, UTF-16 code units) against
// text as C++ holds it (UTF-8 bytes), and file URIs against paths.
#pragma once
#include <string>

namespace crossrt::lsp {

// The byte offset of (line, UTF-16 character) in `text`, clamped to the text and the line.
size_t OffsetOfPosition(const std::string& text, unsigned line, unsigned character);
// The UTF-16 character of 0-based byte column `byteColumn` on `line` of `text`.
unsigned CharacterOfColumn(const std::string& text, unsigned line, unsigned byteColumn);
// Line `line` (0-based) of `text`, without its end.
std::string LineOf(const std::string& text, unsigned line);

// file:///a/b%20c.cpp -> /a/b c.cpp; "" for anything but a file URI.
std::string PathOfUri(const std::string& uri);
std::string UriOfPath(const std::string& path);

}  // namespace crossrt::lsp
