// Which of a target's source files define a class's member functions, whatever their names.
//
// crossrt_add_class() without SOURCES hands the client every C++ source of the target. Most of
// them (main.cpp above all) are not the class's: they may even include the headers this very
// translation generates. The finder reads the candidates as text (no parsing) and keeps those with
// an out-of-line member definition, `Render::Render(...) :` or `void Render::Run(...) {`. A class
// whose members are all defined in its header is found through the headers the candidates include.
#pragma once
#include <string>
#include <vector>

namespace crossrt::client {

struct SourceSelection {
  std::vector<std::string> sources;  // what to parse: the defining .cpp files, or the class's header
  std::string error;                 // why nothing was found (then sources is empty)
};

// `className` may be qualified (demo::Render); `includeDirs` are the -I directories of the target,
// searched for quoted includes after the including file's own directory.
SourceSelection FindClassSources(const std::string& className, const std::vector<std::string>& candidates,
                                 const std::vector<std::string>& includeDirs);

}  // namespace crossrt::client
