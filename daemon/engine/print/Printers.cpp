// The printers, by target language (Printers.h).
#include "print/Printers.h"
#include "print/glsl/GlslPrinter.h"
#include "print/ispc/IspcPrinter.h"

namespace crossrt::engine {

std::unique_ptr<KernelPrinter> MakePrinter(TargetLanguage language, clang::ASTContext& ctx, const clang::CXXRecordDecl* cls, Reporter& reporter) {
  if (language == TargetLanguage::Ispc) return std::make_unique<IspcPrinter>(ctx, cls, reporter);
  return std::make_unique<GlslPrinter>(ctx, cls, reporter);
}

std::unique_ptr<KernelPrinter> MakePrinter(const ClassModel& model, clang::ASTContext& ctx, const clang::CXXRecordDecl* cls, Reporter& reporter) {
  return MakePrinter(model.forIspc ? TargetLanguage::Ispc : TargetLanguage::Glsl, ctx, cls, reporter);
}

}  // namespace crossrt::engine
