// Canonical form of C++ code copied from the user's sources into generated files: comments are
// dropped and the layout comes from clang-format, so an edit to a comment or to whitespace in the
// user's code leaves the generated files byte-identical (and nothing generated recompiles). The
// generated files as a whole get the same layout.
#pragma once
#include <string>

namespace crossrt::engine {

std::string CanonicalCode(const std::string& code);

// A generated C++ file laid out as the project's own code is (clang-format, lines of at most 120
// characters, comments kept and rewrapped where too long).
std::string FormattedGeneratedCode(const std::string& code);

}  // namespace crossrt::engine
