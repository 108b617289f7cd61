// Parsed translation units, kept between translations.
//
// Each entry is a ParsedFile keyed by (source file, compile arguments). The first request builds a
// precompiled preamble (the #include block) in memory and parses the file over it; later ones parse
// the file again over the same preamble as long as no header changed: milliseconds instead of a
// few hundred. A header edit rebuilds only the user's part of the preamble, over a kept PCH of the
// system headers the source starts with (SystemLayer.h). The preamble skips the bodies of functions
// in system headers (the C++ library), which kernels call by name, if at all; the user's headers
// keep theirs. The cache holds at most `capacity` entries and evicts the least recently used. An
// AstCache that a single translation creates and drops gives plain, uncached parsing.
#pragma once
#include "parse/IncludesSeen.h"

#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace clang {
class ASTContext;
class CompilerInstance;
class DiagnosticsEngine;
class LangOptions;
class Preprocessor;
class SourceManager;
class TextDiagnosticPrinter;
}  // namespace clang

namespace crossrt::engine {

class SystemLayerCache;

// One parsed source file: the compiler instance that holds its AST, and the accessors the
// translator uses (named as clang::ASTUnit names them).
class ParsedFile {
public:
  ParsedFile(std::unique_ptr<clang::CompilerInstance> compiler, IncludesSeen includes);
  ~ParsedFile();
  clang::ASTContext& getASTContext() const;
  clang::SourceManager& getSourceManager() const;
  clang::Preprocessor& getPreprocessor() const;
  const clang::LangOptions& getLangOpts() const;
  clang::DiagnosticsEngine& getDiagnostics() const;
  const IncludesSeen& Includes() const { return m_includes; }  // in the preamble and after it

private:
  std::unique_ptr<clang::CompilerInstance> m_compiler;
  IncludesSeen m_includes;
};

struct AstCacheStats {
  size_t entries = 0, capacity = 0;
  uint64_t parses = 0;     // from scratch
  uint64_t reparses = 0;   // reusing a cached AST and its preamble
  uint64_t reuses = 0;     // of those, an AST used as it was: nothing it read had changed
  uint64_t layers = 0;             // system layers built or tried (SystemLayer.h)
  uint64_t layeredPreambles = 0;   // preambles built over one
};

class AstCache {
public:
  // When a cache that lives for many translations builds a source's system layer (SystemLayer.h)
  // in the background, so that a header edit finds it ready: never (the layer is built by the first
  // header edit), once the source is parsed again (it is being edited: the build daemon's choice,
  // whose cold builds parse hundreds of classes once each), or after its first parse (an editor has
  // opened it: the language server's).
  enum class LayerPreparation { None, AfterReparse, AfterParse };
  explicit AstCache(size_t capacity = 32, LayerPreparation prepare = LayerPreparation::None);
  ~AstCache();
  AstCache(const AstCache&) = delete;
  AstCache& operator=(const AstCache&) = delete;

  // A parsed file, locked for the caller's exclusive use while the handle lives.
  class Handle {
  public:
    ParsedFile* ast() const;
    clang::TextDiagnosticPrinter& printer() const;  // client of ast()'s diagnostics
    const std::string& diagnostics() const;          // what printer() wrote since the (re)parse
    bool failed() const;                             // the parse had errors
    ~Handle();
    Handle(Handle&&) noexcept;
    Handle& operator=(Handle&&) = delete;

  private:
    friend class AstCache;
    struct Entry;
    explicit Handle(std::shared_ptr<Entry> entry);
    std::shared_ptr<Entry> m_entry;
    std::unique_lock<std::mutex> m_lock;  // held while the handle lives
  };

  // Parses `file` with `args` (compiler flags, without the file), or reparses a cached AST, or hands
  // out the cached AST as it is when nothing it read has changed (the same class translated for
  // another backend). Files named in `unsaved` (absolute path -> text: an editor's buffers) are read
  // from there, not from disk; the preamble is rebuilt when a header's unsaved text changes.
  Handle Get(const std::string& file, const std::vector<std::string>& args,
             const std::map<std::string, std::string>& unsaved = {});

  AstCacheStats Stats() const;

private:
  mutable std::mutex m_mutex;
  size_t m_capacity;
  LayerPreparation m_prepare;
  uint64_t m_parses = 0, m_reparses = 0, m_reuses = 0, m_layeredPreambles = 0;
  std::map<std::string, std::shared_ptr<Handle::Entry>> m_entries;
  std::list<std::string> m_lru;  // most recently used first
  std::unique_ptr<SystemLayerCache> m_layers;  // the system headers' layers of preambles, shared
};

}  // namespace crossrt::engine
