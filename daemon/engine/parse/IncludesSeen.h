// What the parser saw of #include lines. The AST does not keep them once a precompiled preamble
// holds the #include block, so the AST cache records them while it parses, and the analysis and
// the depfile read them here.
#pragma once
#include <map>
#include <set>
#include <string>

namespace crossrt::engine {

struct IncludesSeen {
  std::map<unsigned, std::string> mainFile;  // line of an #include in the main file -> the file it found
  std::set<std::string> files;               // the main file, and every file an #include found
};

}  // namespace crossrt::engine
