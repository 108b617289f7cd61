#include "SourceFinder.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace fs = std::filesystem;

namespace crossrt::client {

namespace {

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

bool IsIdent(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// The text with comments, string and character literals blanked out (raw strings too), so that a
// name mentioned there is not taken for code.
std::string CodeOnly(const std::string& text) {
  std::string out = text;
  for (size_t i = 0; i < out.size();) {
    if (out.compare(i, 2, "//") == 0) {
      while (i < out.size() && out[i] != '\n') out[i++] = ' ';
    } else if (out.compare(i, 2, "/*") == 0) {
      const size_t end = out.find("*/", i + 2);
      const size_t stop = end == std::string::npos ? out.size() : end + 2;
      for (; i < stop; ++i)
        if (out[i] != '\n') out[i] = ' ';
    } else if (out[i] == 'R' && i + 1 < out.size() && out[i + 1] == '"' && (i == 0 || !IsIdent(out[i - 1]))) {
      const size_t open = out.find('(', i);
      if (open == std::string::npos) break;
      const std::string close = ")" + out.substr(i + 2, open - i - 2) + "\"";
      const size_t end = out.find(close, open);
      const size_t stop = end == std::string::npos ? out.size() : end + close.size();
      for (; i < stop; ++i)
        if (out[i] != '\n') out[i] = ' ';
    } else if (out[i] == '"' || (out[i] == '\'' && (i == 0 || !std::isxdigit(static_cast<unsigned char>(out[i - 1]))))) {
      const char quote = out[i];
      out[i++] = ' ';
      while (i < out.size() && out[i] != quote && out[i] != '\n') {
        if (out[i] == '\\' && i + 1 < out.size()) out[i++] = ' ';
        out[i++] = ' ';
      }
      if (i < out.size() && out[i] == quote) out[i++] = ' ';
    } else {
      ++i;
    }
  }
  return out;
}

size_t SkipSpace(const std::string& s, size_t i) {
  while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return i;
}

// The position after the bracket that closes the one at `open` ('(' or '<'), or npos.
size_t SkipBalanced(const std::string& s, size_t open) {
  const char o = s[open], c = o == '(' ? ')' : '>';
  int depth = 0;
  for (size_t i = open; i < s.size(); ++i) {
    if (s[i] == o) ++depth;
    else if (s[i] == c && --depth == 0) return i + 1;
    else if (o == '<' && (s[i] == ';' || s[i] == '{')) return std::string::npos;
  }
  return std::string::npos;
}

// Whether the code defines a member of class `name` outside the class: `Name::f(...)` followed by a
// body, a constructor's initialiser list, qualifiers or `= default`, rather than by `;` (a call).
bool DefinesMembers(const std::string& code, const std::string& name) {
  for (size_t at = code.find(name); at != std::string::npos; at = code.find(name, at + 1)) {
    if ((at > 0 && IsIdent(code[at - 1])) || (at + name.size() < code.size() && IsIdent(code[at + name.size()]))) continue;
    if (at > 0 && (code[at - 1] == '.' || (at > 1 && code.compare(at - 2, 2, "->") == 0))) continue;
    size_t i = SkipSpace(code, at + name.size());
    if (i < code.size() && code[i] == '<') {  // Name<T>::f
      i = SkipBalanced(code, i);
      if (i == std::string::npos) continue;
      i = SkipSpace(code, i);
    }
    if (code.compare(i, 2, "::") != 0) continue;
    i = SkipSpace(code, i + 2);
    if (i < code.size() && code[i] == '~') i = SkipSpace(code, i + 1);
    const size_t identStart = i;
    while (i < code.size() && IsIdent(code[i])) ++i;
    if (i == identStart) continue;
    const bool isOperator = code.compare(identStart, i - identStart, "operator") == 0;
    if (isOperator)
      while (i < code.size() && code[i] != '(') ++i;  // operator+=, operator() ...
    else
      i = SkipSpace(code, i);
    if (i >= code.size() || code[i] != '(') continue;
    if (isOperator && code.compare(i, 2, "()") == 0) i = SkipSpace(code, i + 2);
    i = SkipBalanced(code, i);
    if (i == std::string::npos) continue;
    i = SkipSpace(code, i);
    if (i >= code.size()) continue;
    if (code[i] == '{' || code[i] == '&' || code[i] == '=' || code.compare(i, 2, "->") == 0) return true;
    if (code[i] == ':' && code.compare(i, 2, "::") != 0) return true;
    size_t w = i;
    while (w < code.size() && IsIdent(code[w])) ++w;
    static const std::set<std::string> qualifiers = {"const", "noexcept", "override", "final", "volatile", "try", "__attribute__"};
    if (qualifiers.count(code.substr(i, w - i))) return true;
  }
  return false;
}

// Whether the code holds the class's definition: `class Name {`, `struct Name final : Base {`.
bool DefinesClass(const std::string& code, const std::string& name) {
  for (const char* keyword : {"class", "struct"}) {
    const std::string k = keyword;
    for (size_t at = code.find(k); at != std::string::npos; at = code.find(k, at + 1)) {
      if ((at > 0 && IsIdent(code[at - 1])) || !std::isspace(static_cast<unsigned char>(code[at + k.size()]))) continue;
      size_t i = SkipSpace(code, at + k.size());
      if (code.compare(i, name.size(), name) != 0 || (i + name.size() < code.size() && IsIdent(code[i + name.size()]))) continue;
      i = SkipSpace(code, i + name.size());
      if (code.compare(i, 5, "final") == 0) i = SkipSpace(code, i + 5);
      if (i < code.size() && (code[i] == '{' || (code[i] == ':' && code.compare(i, 2, "::") != 0))) return true;
    }
  }
  return false;
}

// The files a file includes with quotes, resolved as a compiler would: next to it, then in the
// include directories. Unresolved names (system headers, generated headers) are left out.
std::vector<std::string> QuotedIncludes(const std::string& file, const std::string& text, const std::vector<std::string>& includeDirs) {
  std::vector<std::string> out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    size_t i = SkipSpace(line, 0);
    if (i >= line.size() || line[i] != '#') continue;
    i = SkipSpace(line, i + 1);
    if (line.compare(i, 7, "include") != 0) continue;
    const size_t open = line.find('"', i + 7);
    const size_t close = open == std::string::npos ? open : line.find('"', open + 1);
    if (close == std::string::npos) continue;
    const std::string name = line.substr(open + 1, close - open - 1);
    std::vector<fs::path> places = {fs::path(file).parent_path() / name};
    for (auto& dir : includeDirs) places.push_back(fs::path(dir) / name);
    for (auto& p : places) {
      std::error_code ec;
      if (fs::is_regular_file(p, ec)) {
        out.push_back(fs::weakly_canonical(p, ec).string());
        break;
      }
    }
  }
  return out;
}

std::string Listed(const std::vector<std::string>& files) {
  std::string s;
  for (auto& f : files) s += (s.empty() ? "" : ", ") + fs::path(f).filename().string();
  return s;
}

}  // namespace

SourceSelection FindClassSources(const std::string& className, const std::vector<std::string>& candidates,
                                 const std::vector<std::string>& includeDirs) {
  const size_t colons = className.rfind("::");
  const std::string name = colons == std::string::npos ? className : className.substr(colons + 2);
  SourceSelection result;
  std::vector<std::string> existing;
  for (auto& c : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(c, ec) && std::find(existing.begin(), existing.end(), c) == existing.end()) existing.push_back(c);
  }
  for (auto& c : existing)
    if (DefinesMembers(CodeOnly(ReadText(c)), name)) result.sources.push_back(c);
  if (!result.sources.empty()) return result;

  // Every member is defined in the class body: parse the header that defines the class (or a
  // source that does), found through the candidates' includes.
  std::set<std::string> seen;
  std::vector<std::string> frontier = existing;
  for (int depth = 0; depth < 4 && !frontier.empty(); ++depth) {
    std::vector<std::string> next;
    for (auto& f : frontier) {
      if (!seen.insert(f).second) continue;
      const std::string text = ReadText(f);
      if (DefinesClass(CodeOnly(text), name)) {
        result.sources.push_back(f);
        return result;
      }
      for (auto& inc : QuotedIncludes(f, text, includeDirs)) next.push_back(inc);
    }
    frontier = next;
  }
  result.error = "no source file of the target defines class '" + className + "' or its member functions" +
                 (existing.empty() ? std::string(" (it has no C++ sources)") : " (looked in " + Listed(existing) + " and the headers they include)") +
                 "\nnote: hint: name the files that define " + name + "'s member functions: crossrt_add_class(<target> " + className +
                 " ... SOURCES " + name + ".cpp)";
  return result;
}

}  // namespace crossrt::client
