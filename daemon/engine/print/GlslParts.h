// What the printer's files (Glsl.cpp, GlslCalls.cpp, GlslImages.cpp) share besides GlslPrinter.
#pragma once
#include "print/Glsl.h"

namespace crossrt::engine {

// The field of `this` that `e` names (this->f or f), or null.
const clang::FieldDecl* ThisMemberField(const clang::Expr* e);
// How a texel of the image's type becomes the C++ value: images hold 4 channels on the GPU.
std::string TexelOf(const ImageFormat& f, const std::string& load);
// How GLSL names an image's storage image (a member by its name, a parameter made safe for GLSL),
// and how diagnostics name the image.
std::string ImageName(const clang::ValueDecl* image);
std::string Described(const clang::ValueDecl* image);

}  // namespace crossrt::engine
