// Names the generated code keeps for itself. Everything the generator introduces in GLSL, ISPC and
// C++ begins with crt_ (GeneratedNames.h), so that no name of the user's can collide with it. A
// user's name that begins with crt_ could, without a word: a local shadowing a generated one, a
// member hidden by one. Takes the class; reports each such name as an error, on every backend.
#pragma once
#include "analyse/AnalysisContext.h"

namespace crossrt::engine {

// The class's data members and member functions and their parameters (once: `declarations`), and
// the variables the bodies of its member functions defined in this translation unit declare.
void CheckReservedNames(Context& c, bool declarations);

}  // namespace crossrt::engine
