// What the printers' files (the walk's, and each language's) share besides KernelPrinter.
#pragma once
#include "print/KernelPrinter.h"

namespace crossrt::engine {

// The source text of a range, as written (for comments that say where generated code came from).
std::string TrimmedSourceText(const clang::ASTContext& ctx, clang::SourceRange range);
// A call of f with the printed arguments: "f(a, b)".
std::string CallText(const std::string& f, const std::vector<std::string>& args);
// The field of `this` that `e` names (this->f or f), or null.
const clang::FieldDecl* ThisMemberField(const clang::Expr* e);
// How a texel of the image's type becomes the C++ value: images hold 4 channels on the GPU.
std::string TexelOf(const ImageFormat& f, const std::string& load);
// How GLSL names an image's storage image (a member by its name, a parameter made safe for GLSL),
// and how diagnostics name the image.
std::string ImageName(const clang::ValueDecl* image);
std::string Described(const clang::ValueDecl* image);

}  // namespace crossrt::engine
