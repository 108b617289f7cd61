// The printers, by target language: the one place that knows them all. The analysis asks for the
// printer of its backend's language and walks kernels through KernelPrinter alone.
#pragma once
#include "Model.h"
#include "print/KernelPrinter.h"

#include <memory>

namespace crossrt::engine {

enum class TargetLanguage { Glsl, Ispc };

std::unique_ptr<KernelPrinter> MakePrinter(TargetLanguage language, clang::ASTContext& ctx, const clang::CXXRecordDecl* cls, Reporter& reporter);
// The printer of the model's backend: ISPC for the ISPC class, GLSL for the Vulkan class (the CPU
// class prints no kernels, but its analysis walks them as the Vulkan class's does).
std::unique_ptr<KernelPrinter> MakePrinter(const ClassModel& model, clang::ASTContext& ctx, const clang::CXXRecordDecl* cls, Reporter& reporter);

}  // namespace crossrt::engine
