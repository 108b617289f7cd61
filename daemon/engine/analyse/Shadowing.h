// Locals that shadow a parameter, an outer local or a namespace constant, and the names they take
// in generated code (Shadowing.cpp).
#pragma once
#include <clang/AST/ASTContext.h>

#include <string>

namespace crossrt::engine {

// The name `vd` takes in generated code where it shadows a name of an enclosing scope (n_1 where
// it shadows n); empty where it shadows none.
std::string ShadowingLocalName(clang::ASTContext& ctx, const clang::VarDecl* vd);

}  // namespace crossrt::engine
