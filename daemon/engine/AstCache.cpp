// Parsed translation units, kept between translations (AstCache.h says how): parse once, then reparse
// with the precompiled preamble; least recently used entries are evicted.
#include "AstCache.h"

#include <clang/Basic/DiagnosticOptions.h>
#include <clang/Frontend/ASTUnit.h>
#include <clang/Frontend/CompilerInstance.h>
#include <clang/Frontend/TextDiagnosticPrinter.h>
#include <clang/Serialization/PCHContainerOperations.h>
#include <llvm/Support/raw_ostream.h>

#include <algorithm>

#ifndef CROSSRT_CLANG_RESOURCE_DIR
#error "CROSSRT_CLANG_RESOURCE_DIR must point at Clang's resource directory"
#endif

namespace crossrt::engine {

namespace {
// Counts the errors it prints, in a count only Get() resets. The consumer's own count does not
// survive the parse: an error in a header (the preamble) would read as a clean parse.
class ErrorCountingPrinter : public clang::TextDiagnosticPrinter {
public:
  using TextDiagnosticPrinter::TextDiagnosticPrinter;
  void HandleDiagnostic(clang::DiagnosticsEngine::Level level, const clang::Diagnostic& info) override {
    if (level >= clang::DiagnosticsEngine::Error) ++errors;
    TextDiagnosticPrinter::HandleDiagnostic(level, info);
  }
  unsigned errors = 0;
};
}  // namespace

struct AstCache::Handle::Entry {
  std::mutex inUse;  // one translation at a time per AST
  std::string diagText;
  llvm::raw_string_ostream diagStream{diagText};
  std::unique_ptr<ErrorCountingPrinter> printer;
  clang::IntrusiveRefCntPtr<clang::DiagnosticsEngine> diags;
  std::unique_ptr<clang::ASTUnit> ast;
  bool failed = false;
};

AstCache::Handle::Handle(std::shared_ptr<Entry> entry) : m_entry(std::move(entry)), m_lock(m_entry->inUse) {}
AstCache::Handle::Handle(Handle&& other) noexcept : m_entry(std::move(other.m_entry)), m_lock(std::move(other.m_lock)) {}
AstCache::Handle::~Handle() = default;
clang::ASTUnit* AstCache::Handle::ast() const { return m_entry->ast.get(); }
clang::TextDiagnosticPrinter& AstCache::Handle::printer() const { return *m_entry->printer; }
const std::string& AstCache::Handle::diagnostics() const {
  m_entry->diagStream.flush();
  return m_entry->diagText;
}
bool AstCache::Handle::failed() const { return m_entry->failed || !m_entry->ast; }

AstCache::AstCache(size_t capacity) : m_capacity(std::max<size_t>(1, capacity)) {}
AstCache::~AstCache() = default;

AstCache::Handle AstCache::Get(const std::string& file, const std::vector<std::string>& args) {
  std::string key = file;
  for (auto& a : args) key += '\x1f' + a;

  std::shared_ptr<Handle::Entry> entry;
  {
    std::lock_guard<std::mutex> guard(m_mutex);
    auto it = m_entries.find(key);
    if (it == m_entries.end()) {
      entry = std::make_shared<Handle::Entry>();
      m_entries[key] = entry;
    } else {
      entry = it->second;
    }
    m_lru.remove(key);
    m_lru.push_front(key);
    // Evict the least recently used entries that nobody is using.
    for (auto victim = m_lru.end(); m_entries.size() > m_capacity && victim != m_lru.begin();) {
      --victim;
      auto e = m_entries.find(*victim);
      if (e->second == entry || e->second.use_count() > 1) continue;
      m_entries.erase(e);
      victim = m_lru.erase(victim);
    }
  }

  Handle handle(entry);  // waits while another translation uses this AST
  entry->diagStream.flush();
  entry->diagText.clear();
  // Decided under the entry's lock: another request may have parsed it meanwhile. A parse that
  // failed is not reparsed: its preamble keeps header errors without reporting them again.
  if (entry->ast && !entry->failed) {
    // Reparse() reuses the preamble when the headers it covers are unchanged.
    entry->printer->clear();
    entry->printer->errors = 0;
    entry->diags->Reset(/*soft=*/true);
    auto pch = std::make_shared<clang::PCHContainerOperations>();
    entry->failed = entry->ast->Reparse(pch) || entry->printer->errors > 0;
    std::lock_guard<std::mutex> guard(m_mutex);
    ++m_reparses;
    return handle;
  }

  // A failed parse's objects go in dependency order: the AST uses the engine, which uses the printer.
  entry->ast.reset();
  entry->diags.reset();
  auto* options = new clang::DiagnosticOptions();
  options->ShowColors = false;
  entry->printer = std::make_unique<ErrorCountingPrinter>(entry->diagStream, options);
  entry->diags = clang::CompilerInstance::createDiagnostics(options, entry->printer.get(), /*ShouldOwnClient=*/false);
  std::vector<const char*> argv = {"clang++"};
  for (auto& a : args) argv.push_back(a.c_str());
  argv.push_back(file.c_str());
  entry->ast = clang::ASTUnit::LoadFromCommandLine(
      argv.data(), argv.data() + argv.size(), std::make_shared<clang::PCHContainerOperations>(), entry->diags,
      CROSSRT_CLANG_RESOURCE_DIR, /*StorePreamblesInMemory=*/true, /*PreambleStoragePath=*/"",
      /*OnlyLocalDecls=*/false, clang::CaptureDiagsKind::None, /*RemappedFiles=*/{},
      /*RemappedFilesKeepOriginalName=*/true, /*PrecompilePreambleAfterNParses=*/1);
  entry->failed = !entry->ast || entry->printer->errors > 0;
  std::lock_guard<std::mutex> guard(m_mutex);
  ++m_parses;
  return handle;
}

AstCacheStats AstCache::Stats() const {
  std::lock_guard<std::mutex> guard(m_mutex);
  return {m_entries.size(), m_capacity, m_parses, m_reparses};
}

}  // namespace crossrt::engine
