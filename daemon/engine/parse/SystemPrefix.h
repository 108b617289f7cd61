// The system headers at the head of a preamble, which may be precompiled apart from the user's.
//
// A preamble is a source's #include block, precompiled. An edit to one of the user's headers
// invalidates all of it, although its C++ library part, most of its cost, has not changed. So the
// AST cache builds a preamble in two layers (SystemLayer.h): the system headers that come first,
// precompiled once and shared, and the rest of the preamble over them, a chained PCH.
//
// The system prefix is the list of system headers that the user's files include with angle
// brackets before anything of theirs that could change how a system header reads, or that a system
// header's inclusion could change. Up to there the user's files contribute only include guards,
// `#pragma once`, conditionals on built-in macros and includes, so a file that includes the same
// system headers in the same order, and nothing else, parses them exactly as they parse in place.
// The prefix ends at the first of:
// - a token from a user's file (a declaration a system template could see);
// - a macro defined or undefined in a user's file, other than a file's include guard (the
//   `#ifndef X` / `#define X` that opens the file and an `#endif` that closes it);
// - a `#pragma` in a user's file other than `#pragma once`;
// - a user's file asking about a macro that a system header defined (`#ifdef`, `defined`, an
//   expansion): with the layer in front, the answer could come earlier than in place;
// - a quoted #include that finds a system header (the includer's folder was searched first), or one
//   that finds nothing.
// The layer's build checks that it read no user file; the preamble's build over it records the
// prefix again and keeps the layer only if it finds the same one.
#pragma once
#include <string>
#include <vector>

namespace clang {
class Preprocessor;
}

namespace crossrt::engine {

struct SystemPrefix {
  std::vector<std::string> includes;  // as written between the angle brackets, in order
  bool operator==(const SystemPrefix& other) const { return includes == other.includes; }
  bool operator!=(const SystemPrefix& other) const { return !(*this == other); }
};

// Records the system prefix of what `pp` preprocesses from now on into `prefix`, which must outlive
// the preprocessor's run. Takes over `pp`'s token watcher.
void RecordSystemPrefix(clang::Preprocessor& pp, SystemPrefix& prefix);

}  // namespace crossrt::engine
