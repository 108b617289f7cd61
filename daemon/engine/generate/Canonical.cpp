// Canonical form of copied C++ and the layout of generated files, both through clang-format
// (Canonical.h says why).
#include "generate/Canonical.h"

#include <clang/Basic/LangOptions.h>
#include <clang/Format/Format.h>
#include <clang/Lex/Lexer.h>
#include <clang/Tooling/Core/Replacement.h>

#include <map>
#include <mutex>

namespace crossrt::engine {

namespace {

// clang-format in the layout of generated code: Allman braces (but lambdas'), 2-space indents,
// `float* p`, two spaces before a trailing comment; `wholeFile`: one-line inline functions stay on
// their line.
std::string Reformat(const std::string& code, unsigned columns, bool wholeFile) {
  clang::format::FormatStyle style = clang::format::getLLVMStyle();
  // Allman's braces, but a lambda's body opens on its line and is indented from the statement (the
  // chunks of a parallel loop: crossrt::ParallelFor(..., [&](int crt_first, int crt_last) {).
  style.BreakBeforeBraces = clang::format::FormatStyle::BS_Custom;
  auto& wrap = style.BraceWrapping;
  wrap.AfterCaseLabel = wrap.AfterClass = wrap.AfterEnum = wrap.AfterFunction = wrap.AfterNamespace = wrap.AfterStruct = wrap.AfterUnion = true;
  wrap.AfterExternBlock = wrap.BeforeCatch = wrap.BeforeElse = true;
  wrap.AfterControlStatement = clang::format::FormatStyle::BWACS_Always;
  wrap.BeforeLambdaBody = false;
  style.LambdaBodyIndentation = clang::format::FormatStyle::LBI_OuterScope;
  style.IndentWidth = 2;
  style.ColumnLimit = columns;
  style.AllowShortFunctionsOnASingleLine = clang::format::FormatStyle::SFS_None;
  style.AllowShortIfStatementsOnASingleLine = clang::format::FormatStyle::SIS_Never;
  style.AllowShortLoopsOnASingleLine = false;
  if (wholeFile) {
    style.AllowShortFunctionsOnASingleLine = clang::format::FormatStyle::SFS_InlineOnly;
    style.PointerAlignment = clang::format::FormatStyle::PAS_Left;
    style.SpacesBeforeTrailingComments = 2;
    style.AlignEscapedNewlines = clang::format::FormatStyle::ENAS_DontAlign;
  }
  auto replacements = clang::format::reformat(style, code, {clang::tooling::Range(0, unsigned(code.size()))});
  auto formatted = clang::tooling::applyAllReplacements(code, replacements);
  return formatted ? *formatted : code;
}

// Reformat, remembered: the daemon lays out the same text again after an edit that changed another
// file (most of a class's files stay the same when one kernel changes). Bounded by what it holds.
std::string Format(const std::string& code, unsigned columns, bool wholeFile = false) {
  static std::mutex mutex;
  static std::map<std::string, std::string> laidOut;
  static size_t bytes = 0;
  const std::string key = std::to_string(columns) + (wholeFile ? "w" : "s") + code;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (auto it = laidOut.find(key); it != laidOut.end()) return it->second;
  }
  std::string formatted = Reformat(code, columns, wholeFile);
  std::lock_guard<std::mutex> lock(mutex);
  if (bytes > (64u << 20)) laidOut.clear(), bytes = 0;
  bytes += key.size() + formatted.size();
  laidOut.emplace(key, formatted);
  return formatted;
}

}  // namespace

std::string FormattedGeneratedCode(const std::string& code) {
  return Format(code, 120, true);
}

std::string CanonicalCode(const std::string& code) {
  clang::LangOptions lang;
  lang.CPlusPlus = lang.CPlusPlus11 = lang.CPlusPlus14 = lang.CPlusPlus17 = true;
  // Re-emit the tokens without comments or the user's spacing; preprocessor lines (the OpenMP
  // pragmas the CPU backend inserts) keep a line of their own.
  clang::Lexer lexer(clang::SourceLocation(), lang, code.data(), code.data(), code.data() + code.size());
  std::string flat;
  bool skippingDirective = false;
  clang::Token tok;
  while (true) {
    lexer.LexFromRawLexer(tok);
    if (tok.is(clang::tok::eof)) break;
    size_t begin = lexer.getCurrentBufferOffset() - tok.getLength();
    if (skippingDirective && !tok.isAtStartOfLine()) continue;
    skippingDirective = false;
    if (tok.is(clang::tok::hash) && tok.isAtStartOfLine()) {
      size_t eol = code.find('\n', begin);
      flat += "\n" + code.substr(begin, eol == std::string::npos ? std::string::npos : eol - begin) + "\n";
      skippingDirective = true;
      continue;
    }
    // Whitespace in the user's code becomes one space; clang-format decides the rest.
    if (!flat.empty() && flat.back() != '\n' && (tok.hasLeadingSpace() || tok.isAtStartOfLine())) flat += " ";
    flat.append(code, begin, tok.getLength());
  }

  std::string out = Format(flat, 110);
  size_t first = out.find_first_not_of(" \n");
  if (first == std::string::npos) return "";
  out.erase(0, first);
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

}  // namespace crossrt::engine
