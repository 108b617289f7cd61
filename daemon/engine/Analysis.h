// Finds kernels, control functions, members and reductions in the user's class (one AST at a time).
#pragma once
#include "Diagnostics.h"
#include "Model.h"

#include <clang/AST/ASTContext.h>

namespace crossrt::engine {

// Adds what this translation unit defines to `model`. The first call (the first source file) also
// fills in members and constructors. Returns false when the class is not declared in this AST.
bool AnalyzeTranslationUnit(clang::ASTContext& ctx, const std::string& className, Reporter& reporter, ClassModel& model);

// After every AST was analysed: builds the class-data block, marks used members. Reports what
// only the whole picture shows (e.g. a control function calling an unknown kernel).
void FinishModel(ClassModel& model);

}  // namespace crossrt::engine
