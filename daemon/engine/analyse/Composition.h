// Composition (paper 3.6): a member of an interface type with an implementation given by COMPOSE. The
// implementation's methods that kernels call are printed into the kernels, its data becomes buffers and
// class data reached through the holder. Takes the implementation's AST; adds to the kernels.
#pragma once
#include "analyse/AnalysisContext.h"

namespace crossrt::engine {

// The definition of `name` an implementation provides (itself or a base that is not abstract there).
const CXXMethodDecl* ImplementationOf(const CXXRecordDecl* impl, const std::string& name, const FunctionDecl*& def);

std::string StructName(const std::string& chunk);

}  // namespace crossrt::engine
