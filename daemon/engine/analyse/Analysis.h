// Finds kernels, control functions, members and reductions in the user's class (one AST at a time).
#pragma once
#include "Diagnostics.h"
#include "parse/IncludesSeen.h"
#include "Model.h"

#include <clang/AST/ASTContext.h>

#include <map>
#include <string>

namespace crossrt::engine {

// Adds what this translation unit defines to `model`. The first call (the first source file) also
// fills in members and constructors. Returns false when the class is not declared in this AST.
// `includes`: what the parse of this AST saw of #include lines.
// `compositions` maps interfaces to the implementations the GPU code uses ("ISceneObject" -> "BVHScene").
bool AnalyzeTranslationUnit(clang::ASTContext& ctx, const IncludesSeen& includes, const std::string& className,
                            const std::map<std::string, std::string>& compositions, Reporter& reporter, ClassModel& model);

// After AnalyzeTranslationUnit saw every AST: merges the code and data of composed implementations
// defined in this AST into the kernels that call them. Returns true when it resolved any.
bool ComposeFromTranslationUnit(clang::ASTContext& ctx, Reporter& reporter, ClassModel& model);

// After every AST was analysed: builds the class-data block, marks used members. Reports what
// only the whole picture shows (e.g. a control function calling an unknown kernel).
void FinishModel(ClassModel& model);

}  // namespace crossrt::engine
