// What a translation request says, made usable: the compile flags Clang parses with (those that
// change the class's meaning), how generated code spells an include, and a source that includes
// a header translations generate.
#include "parse/Arguments.h"

#include <llvm/ADT/SmallString.h>
#include <llvm/Support/FileSystem.h>
#include <llvm/Support/Path.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <regex>

namespace crossrt::engine {

namespace {

// The target's flags that change what the class means to Clang: include paths, macros, the
// language standard, target and feature flags. The rest (warnings, optimisation, GCC-only
// spellings) is dropped: the class is only parsed, and an unknown flag would stop Clang.
bool KeepFlag(const std::string& a) {
  static const char* prefixes[] = {"-D", "-U", "-I", "-std=", "-m", "-isystem", "-iquote", "-include", "-fopenmp",
                                   "-fno-exceptions", "-fno-rtti", "-fexceptions", "-frtti", "-fchar8_t", "-fno-char8_t",
                                   "-ffast-math", "-fno-fast-math", "-ffp-contract="};
  for (const char* p : prefixes)
    if (a.rfind(p, 0) == 0) return true;
  return false;
}

std::vector<std::string> FilterFlags(const std::vector<std::string>& in) {
  std::vector<std::string> out;
  // The language standard: the highest of -std=c++NN and CMake's cxx_std_NN compile features.
  int standard = 0;
  for (auto& a : in) {
    std::string digits = a.rfind("-std=c++", 0) == 0 ? a.substr(8) : a.rfind("-std=gnu++", 0) == 0 ? a.substr(10)
                         : a.rfind("cxx_std_", 0) == 0 ? a.substr(8) : "";
    if (!digits.empty() && std::isdigit(static_cast<unsigned char>(digits[0]))) standard = std::max(standard, std::atoi(digits.c_str()));
  }
  if (standard > 0) out.push_back("-std=c++" + std::to_string(standard));
  for (size_t i = 0; i < in.size(); ++i) {
    const std::string& a = in[i];
    if (a.rfind("-std=", 0) == 0) continue;  // chosen above
    bool takesValue = a == "-I" || a == "-D" || a == "-U" || a == "-isystem" || a == "-iquote" || a == "-include";
    if (!KeepFlag(a)) continue;
    out.push_back(a);
    if (takesValue && i + 1 < in.size()) out.push_back(in[++i]);
  }
  return out;
}

}  // namespace

// How generated code includes the user's header: relative to an include directory when one
// contains it (keeps the output independent of where the tree lives), else by absolute path.
std::string IncludeSpelling(const std::string& header, const std::vector<std::string>& args) {
  std::string best;
  for (size_t i = 0; i < args.size(); ++i) {
    std::string dir;
    if (args[i] == "-I" || args[i] == "-isystem") { if (i + 1 < args.size()) dir = args[i + 1]; }
    else if (args[i].rfind("-I", 0) == 0) dir = args[i].substr(2);
    if (dir.empty()) continue;
    llvm::SmallString<256> abs(dir);
    llvm::sys::fs::make_absolute(abs);
    llvm::sys::path::remove_dots(abs, true);
    std::string prefix = std::string(abs.str()) + "/";
    if (header.rfind(prefix, 0) == 0 && (best.empty() || header.size() - prefix.size() < best.size()))
      best = header.substr(prefix.size());
  }
  return best.empty() ? header : best;
}

// A source that includes a header the translation generates (PointStats_Vulkan.h), which does not
// exist yet: main.cpp, say, listed by mistake. Parsing it would bury the user in errors that follow
// from the missing header, so name the problem instead. Empty when there is none.
std::string GeneratedIncludeProblem(const std::string& source, const std::vector<std::string>& args) {
  static const std::regex generated(R"(^[ \t]*#[ \t]*include[ \t]*[<"](([^>"]*/)?\w+_(Vulkan|CPU|ISPC)\.h)[>"])");
  std::vector<std::string> dirs = {llvm::sys::path::parent_path(source).str()};
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "-I" && i + 1 < args.size()) dirs.push_back(args[i + 1]);
    else if (args[i].rfind("-I", 0) == 0 && args[i].size() > 2) dirs.push_back(args[i].substr(2));
  }
  std::ifstream in(source);
  unsigned lineNo = 0;
  for (std::string line; std::getline(in, line);) {
    ++lineNo;
    std::smatch m;
    if (!std::regex_search(line, m, generated)) continue;
    const std::string name = m[1].str();
    if (std::any_of(dirs.begin(), dirs.end(), [&](const std::string& d) { return llvm::sys::fs::exists(d + "/" + name); })) continue;
    const std::string file = llvm::sys::path::filename(source).str();
    return source + ":" + std::to_string(lineNo) + ":" + std::to_string(m.position(1) + 1) + ": error: " + file + " includes '" + name +
           "', a header that translations generate, so it cannot be parsed to translate a class\n"
           "note: hint: list only the files that define the class's member functions in SOURCES, or leave SOURCES out and "
           "crossrt_add_class finds them\n";
  }
  return "";
}

std::vector<std::string> ParseArguments(const TranslateRequest& request) {
  std::vector<std::string> args = {"-xc++", "-fsyntax-only", "-D__CROSSRT__=1", "-Wno-unused-command-line-argument"};
  auto kept = FilterFlags(request.compileArgs);
  bool hasStandard = std::any_of(kept.begin(), kept.end(), [](const std::string& a) { return a.rfind("-std=", 0) == 0; });
  if (!hasStandard) args.push_back("-std=c++17");  // the least the LiteMath headers need
  args.insert(args.end(), kept.begin(), kept.end());
  return args;
}

bool AllowsContraction(const std::vector<std::string>& args) {
  bool allowed = false;  // x86-64 without -mfma rounds every multiply and add: the default
  for (const auto& a : args) {
    if (a == "-ffast-math" || a == "-ffp-contract=fast") allowed = true;
    if (a == "-fno-fast-math" || a == "-ffp-contract=off" || a == "-ffp-contract=on") allowed = false;
  }
  return allowed;
}

}  // namespace crossrt::engine
