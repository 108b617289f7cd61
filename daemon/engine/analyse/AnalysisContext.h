// What every analysis pass shares: the AST of one translation unit, the user's class in it, the
// reporter of diagnostics and the model being filled (Context). The passes speak Clang's AST throughout.
#pragma once
#include "analyse/Analysis.h"
#include "generate/Canonical.h"
#include "print/KernelPrinter.h"

#include <clang/AST/ParentMapContext.h>
#include <clang/AST/RecursiveASTVisitor.h>
#include <clang/Basic/SourceManager.h>
#include <clang/Lex/Lexer.h>
#include <clang/Rewrite/Core/Rewriter.h>

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace crossrt::engine {
using namespace clang;

std::string Text(const ASTContext& ctx, SourceRange range);

struct Context {
  ASTContext& ctx;
  const CXXRecordDecl* cls;
  Reporter& rep;
  ClassModel& model;
  const std::map<std::string, std::string>& compositions;  // interface -> implementation
  std::set<std::string> appended;  // member vectors some kernel push_backs to
  // (kernel, parameter) pairs a control function's thread loop passes a local's address to.
  std::set<std::pair<std::string, std::string>> threadState;
  std::string Text(SourceRange r) const { return engine::Text(ctx, r); }
};

}  // namespace crossrt::engine
