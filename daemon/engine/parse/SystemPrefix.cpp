// Finds a preamble's system prefix while the preamble builds (SystemPrefix.h says what it is): a
// preprocessor callback over the user's files' directives, and a token watcher for their first token.
#include "parse/SystemPrefix.h"

#include <clang/Basic/SourceManager.h>
#include <clang/Lex/MacroInfo.h>
#include <clang/Lex/PPCallbacks.h>
#include <clang/Lex/Preprocessor.h>
#include <llvm/ADT/DenseMap.h>

#include <cctype>
#include <optional>

namespace crossrt::engine {

namespace {

// True when nothing but white space and comments follows the line that `text` starts in.
bool OnlyCommentsAfterLine(llvm::StringRef text) {
  size_t i = text.find('\n');
  if (i == llvm::StringRef::npos) return true;
  while (i < text.size()) {
    if (std::isspace(static_cast<unsigned char>(text[i]))) {
      ++i;
    } else if (text.substr(i).starts_with("//")) {
      i = text.find('\n', i);
      if (i == llvm::StringRef::npos) return true;
    } else if (text.substr(i).starts_with("/*")) {
      i = text.find("*/", i + 2);
      if (i == llvm::StringRef::npos) return false;
      i += 2;
    } else {
      return false;
    }
  }
  return true;
}

// True for `#pragma once` written at the start of `text`.
bool IsPragmaOnce(llvm::StringRef text) {
  text = text.ltrim();
  if (text.consume_front("#")) text = text.ltrim();
  if (!text.consume_front("pragma")) return false;
  text = text.ltrim(" \t");
  if (!text.consume_front("once")) return false;
  return text.empty() || !(std::isalnum(static_cast<unsigned char>(text[0])) || text[0] == '_');
}

class PrefixRecorder : public clang::PPCallbacks {
public:
  PrefixRecorder(const clang::SourceManager& sm, SystemPrefix& out) : m_sm(sm), m_out(out) {}

  void Token(const clang::Token& token) {
    if (!m_ended && !token.is(clang::tok::eof) && User(token.getLocation())) End();
  }

  void InclusionDirective(clang::SourceLocation hash, const clang::Token&, llvm::StringRef name, bool angled,
                          clang::CharSourceRange, clang::OptionalFileEntryRef file, llvm::StringRef, llvm::StringRef,
                          const clang::Module*, bool, clang::SrcMgr::CharacteristicKind kind) override {
    if (!Directive(hash)) return;
    if (!file) return End();
    if (!clang::SrcMgr::isSystem(kind)) return;  // a user's header: its directives are watched in turn
    if (!angled) return End();
    m_out.includes.push_back(name.str());
  }

  void MacroDefined(const clang::Token& name, const clang::MacroDirective*) override {
    clang::SourceLocation at = name.getLocation();
    if (m_ended || !User(at)) return;
    File& file = m_files[m_sm.getFileID(m_sm.getExpansionLoc(at))];
    if (file.directives == 1 && file.guard && file.guard == name.getIdentifierInfo()) {
      file.directives++;
      file.guardDefinedAt = m_out.includes.size();
      return;
    }
    End();
  }
  void MacroUndefined(const clang::Token& name, const clang::MacroDefinition&, const clang::MacroDirective*) override {
    if (User(name.getLocation())) End();
  }
  void PragmaDirective(clang::SourceLocation at, clang::PragmaIntroducerKind introducer) override {
    if (m_ended || !User(at)) return;
    if (introducer == clang::PIK_HashPragma && IsPragmaOnce(m_sm.getCharacterData(at))) return;
    End();
  }

  void Ifndef(clang::SourceLocation at, const clang::Token& name, const clang::MacroDefinition& macro) override {
    if (m_ended || !User(at)) return;
    File& file = m_files[m_sm.getFileID(m_sm.getExpansionLoc(at))];
    if (file.directives == 0) {
      file.guard = name.getIdentifierInfo();
      file.guardIf = at;
    }
    file.directives++;
    Asks(macro);
  }
  void Ifdef(clang::SourceLocation at, const clang::Token&, const clang::MacroDefinition& macro) override {
    if (Directive(at)) Asks(macro);
  }
  void Elifdef(clang::SourceLocation at, const clang::Token&, const clang::MacroDefinition& macro) override {
    if (Directive(at)) Asks(macro);
  }
  void Elifndef(clang::SourceLocation at, const clang::Token&, const clang::MacroDefinition& macro) override {
    if (Directive(at)) Asks(macro);
  }
  void Defined(const clang::Token& name, const clang::MacroDefinition& macro, clang::SourceRange) override {
    if (!m_ended && User(name.getLocation())) Asks(macro);
  }
  void MacroExpands(const clang::Token& name, const clang::MacroDefinition& macro, clang::SourceRange,
                    const clang::MacroArgs*) override {
    if (!m_ended && User(name.getLocation())) Asks(macro);
  }
  void If(clang::SourceLocation at, clang::SourceRange, ConditionValueKind) override { Directive(at); }
  void Elif(clang::SourceLocation at, clang::SourceRange, ConditionValueKind, clang::SourceLocation) override {
    Directive(at);
  }
  void Else(clang::SourceLocation at, clang::SourceLocation) override { Directive(at); }

  // The #endif of what looked like an include guard must close the file; otherwise the macro was
  // a setting, defined before the system headers recorded since. Checked after the prefix ended too.
  void Endif(clang::SourceLocation at, clang::SourceLocation ifAt) override {
    if (!User(at)) return;
    Directive(at);
    auto file = m_files.find(m_sm.getFileID(m_sm.getExpansionLoc(at)));
    if (file == m_files.end() || ifAt != file->second.guardIf || !file->second.guardDefinedAt) return;
    if (OnlyCommentsAfterLine(m_sm.getCharacterData(at))) return;
    if (*file->second.guardDefinedAt < m_out.includes.size()) m_out.includes.resize(*file->second.guardDefinedAt);
    End();
  }

private:
  struct File {
    unsigned directives = 0;
    const clang::IdentifierInfo* guard = nullptr;  // named by the file's first directive, an #ifndef
    clang::SourceLocation guardIf;
    std::optional<size_t> guardDefinedAt;  // the prefix's length when the guard was defined
  };

  // A location in a file of the user's (not a system header, the built-in or the command line's
  // macros).
  bool User(clang::SourceLocation at) const {
    at = m_sm.getExpansionLoc(at);
    if (at.isInvalid() || m_sm.isInSystemHeader(at)) return false;
    return m_sm.getFileEntryRefForID(m_sm.getFileID(at)).has_value();
  }
  // Counts a directive of a user's file; false when the prefix has ended or the file is not one.
  bool Directive(clang::SourceLocation at) {
    if (m_ended || !User(at)) return false;
    m_files[m_sm.getFileID(m_sm.getExpansionLoc(at))].directives++;
    return true;
  }
  // A user's file asks about a macro: the prefix ends if a system header defined it.
  void Asks(const clang::MacroDefinition& macro) {
    const clang::MacroInfo* info = macro.getMacroInfo();
    if (info && m_sm.isInSystemHeader(m_sm.getExpansionLoc(info->getDefinitionLoc()))) End();
  }
  void End() { m_ended = true; }

  const clang::SourceManager& m_sm;
  SystemPrefix& m_out;
  bool m_ended = false;
  llvm::DenseMap<clang::FileID, File> m_files;
};

}  // namespace

void RecordSystemPrefix(clang::Preprocessor& pp, SystemPrefix& prefix) {
  prefix = {};
  auto recorder = std::make_unique<PrefixRecorder>(pp.getSourceManager(), prefix);
  PrefixRecorder* watcher = recorder.get();  // the preprocessor owns it, and outlives its watcher
  pp.addPPCallbacks(std::move(recorder));
  pp.setTokenWatcher([watcher](const clang::Token& token) { watcher->Token(token); });
}

}  // namespace crossrt::engine
