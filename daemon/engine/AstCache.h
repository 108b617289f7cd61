// Parsed translation units, kept between translations.
//
// Each entry is a clang::ASTUnit keyed by (source file, compile arguments). The first request
// parses from scratch; later ones call Reparse(), which reuses the precompiled preamble (the
// #include block) kept in memory as long as no header changed: a few tens of milliseconds instead
// of a few hundred. The cache holds at most `capacity` entries and evicts the least recently used.
// An AstCache that a single translation creates and drops gives plain, uncached parsing.
#pragma once
#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace clang {
class ASTUnit;
class TextDiagnosticPrinter;
}  // namespace clang

namespace crossrt::engine {

struct AstCacheStats {
  size_t entries = 0, capacity = 0;
  uint64_t parses = 0;     // from scratch
  uint64_t reparses = 0;   // reusing a cached AST and its preamble
};

class AstCache {
public:
  explicit AstCache(size_t capacity = 32);
  ~AstCache();
  AstCache(const AstCache&) = delete;
  AstCache& operator=(const AstCache&) = delete;

  // A parsed file, locked for the caller's exclusive use while the handle lives.
  class Handle {
  public:
    clang::ASTUnit* ast() const;
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

  // Parses `file` with `args` (compiler flags, without the file), or reparses a cached AST.
  Handle Get(const std::string& file, const std::vector<std::string>& args);

  AstCacheStats Stats() const;

private:
  mutable std::mutex m_mutex;
  size_t m_capacity;
  uint64_t m_parses = 0, m_reparses = 0;
  std::map<std::string, std::shared_ptr<Handle::Entry>> m_entries;
  std::list<std::string> m_lru;  // most recently used first
};

}  // namespace crossrt::engine
