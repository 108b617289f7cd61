// What a translation request says, made usable: the compile flags Clang parses with, how generated
// code spells an include, and a source that includes a header translations generate.
#pragma once
#include "TranslateTypes.h"

#include <string>
#include <vector>

namespace crossrt::engine {

// The compile arguments the engine parses with: the request's that change the class's meaning
// (include paths, macros, the language standard, target flags), plus what the engine adds.
std::vector<std::string> ParseArguments(const TranslateRequest& request);

// How generated code includes `header`: relative to an include directory of `args` when one
// contains it (the output does not depend on where the tree lives), else by absolute path.
std::string IncludeSpelling(const std::string& header, const std::vector<std::string>& args);

// A source that includes a header the translation generates (PointStats_Vulkan.h), which does not
// exist yet: the diagnostic that names it, or empty.
std::string GeneratedIncludeProblem(const std::string& source, const std::vector<std::string>& args);

// Whether the class's flags let the GPU fuse multiplies and adds (-ffast-math, -ffp-contract=fast;
// the last such flag wins). Without them every shader gets NoContraction (NoContraction.h).
bool AllowsContraction(const std::vector<std::string>& args);

}  // namespace crossrt::engine
