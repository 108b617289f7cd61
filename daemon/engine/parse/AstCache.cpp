// Parsed translation units, kept between translations (AstCache.h says how): build a precompiled
// preamble once, then parse the main file over it for each request; least recently used entries
// are evicted.
#include "parse/AstCache.h"

#include "parse/FileStamps.h"
#include "parse/SystemLayer.h"
#include "parse/SystemPrefix.h"

#include <clang/AST/ASTContext.h>
#include <clang/AST/Decl.h>
#include <clang/Basic/DiagnosticOptions.h>
#include <clang/Basic/SourceManager.h>
#include <clang/Frontend/CompilerInstance.h>
#include <clang/Frontend/CompilerInvocation.h>
#include <clang/Frontend/FrontendActions.h>
#include <clang/Frontend/PrecompiledPreamble.h>
#include <clang/Frontend/TextDiagnosticPrinter.h>
#include <clang/Frontend/Utils.h>
#include <clang/Lex/PPCallbacks.h>
#include <clang/Lex/Preprocessor.h>
#include <clang/Lex/PreprocessorOptions.h>
#include <clang/Serialization/PCHContainerOperations.h>
#include <llvm/ADT/SmallString.h>
#include <llvm/Support/MemoryBuffer.h>
#include <llvm/Support/Path.h>
#include <llvm/Support/VirtualFileSystem.h>
#include <llvm/Support/raw_ostream.h>

#include <algorithm>
#include <optional>

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

// Records what the #include directives it sees found: in the preamble's build, and in the parse
// after it (an #include below the first declaration).
class IncludeRecorder : public clang::PPCallbacks {
public:
  IncludeRecorder(const clang::SourceManager& sm, IncludesSeen& seen) : m_sm(sm), m_seen(seen) {}
  void InclusionDirective(clang::SourceLocation hashLoc, const clang::Token&, llvm::StringRef, bool, clang::CharSourceRange,
                          clang::OptionalFileEntryRef file, llvm::StringRef, llvm::StringRef, const clang::Module*, bool,
                          clang::SrcMgr::CharacteristicKind) override {
    if (!file) return;
    m_seen.files.insert(file->getName().str());
    if (m_sm.isWrittenInMainFile(hashLoc)) m_seen.mainFile[m_sm.getSpellingLineNumber(hashLoc)] = file->getName().str();
  }

private:
  const clang::SourceManager& m_sm;
  IncludesSeen& m_seen;
};

// The preamble keeps the bodies of the user's functions (kernels call helpers from headers) and
// drops those in system headers: the C++ library's templates are most of a preamble and most of
// each parse's work (their instantiations), and kernels treat a system header's functions as a
// library's, by name (IsSystemDecl), never printing their bodies.
// It also records the preamble's system prefix (SystemPrefix.h).
class PreambleBodies : public clang::PreambleCallbacks {
public:
  PreambleBodies(IncludesSeen& seen, SystemPrefix& prefix) : m_seen(seen), m_prefix(prefix) {}
  void BeforeExecute(clang::CompilerInstance& compiler) override {
    m_sm = &compiler.getSourceManager();
    RecordSystemPrefix(compiler.getPreprocessor(), m_prefix);
  }
  std::unique_ptr<clang::PPCallbacks> createPPCallbacks() override { return std::make_unique<IncludeRecorder>(*m_sm, m_seen); }
  bool shouldSkipFunctionBody(clang::Decl* decl) override {
    const clang::SourceManager& sm = decl->getASTContext().getSourceManager();
    return sm.isInSystemHeader(sm.getExpansionLoc(decl->getLocation()));
  }

private:
  IncludesSeen& m_seen;
  SystemPrefix& m_prefix;
  const clang::SourceManager* m_sm = nullptr;
};
}  // namespace

ParsedFile::ParsedFile(std::unique_ptr<clang::CompilerInstance> compiler, IncludesSeen includes)
    : m_compiler(std::move(compiler)), m_includes(std::move(includes)) {}
ParsedFile::~ParsedFile() = default;
clang::ASTContext& ParsedFile::getASTContext() const { return m_compiler->getASTContext(); }
clang::SourceManager& ParsedFile::getSourceManager() const { return m_compiler->getSourceManager(); }
clang::Preprocessor& ParsedFile::getPreprocessor() const { return m_compiler->getPreprocessor(); }
const clang::LangOptions& ParsedFile::getLangOpts() const { return m_compiler->getLangOpts(); }
clang::DiagnosticsEngine& ParsedFile::getDiagnostics() const { return m_compiler->getDiagnostics(); }

struct AstCache::Handle::Entry {
  std::mutex inUse;  // one translation at a time per AST
  std::string diagText;
  llvm::raw_string_ostream diagStream{diagText};
  llvm::IntrusiveRefCntPtr<clang::DiagnosticOptions> diagOptions;
  std::unique_ptr<ErrorCountingPrinter> printer;
  std::shared_ptr<clang::CompilerInvocation> invocation;  // from the arguments, before any preamble
  std::string flagsKey;                                    // the arguments, for the system layers' cache
  std::optional<clang::PrecompiledPreamble> preamble;
  IncludesSeen preambleIncludes;  // what the preamble's #include lines found
  // The preamble's system prefix as its last one-layer build found it, and the layer the preamble
  // is built over (null: a one-layer preamble).
  SystemPrefix prefix;
  std::shared_ptr<const SystemLayer> layer;
  bool layersRefused = false;
  bool builtOverLayer = false;  // the last Parse built a preamble over a layer (for the statistics)
  // The last parse. EndParse() drops it action first: the action ends the source file while the
  // compiler and the main file's buffer still live.
  std::unique_ptr<llvm::MemoryBuffer> mainBuffer;
  std::vector<std::unique_ptr<llvm::MemoryBuffer>> unsavedBuffers;  // the headers' unsaved text
  std::unique_ptr<ParsedFile> parsed;
  std::unique_ptr<clang::SyntaxOnlyAction> action;
  bool failed = false;
  // What the last parse read, to tell whether the next request may use its AST as it is: the
  // unsaved buffers, and the size and time of every file it read from disk.
  bool reusable = false;
  std::map<std::string, std::string> parsedUnsaved;
  FileStamps parsedFiles;

  ~Entry() { EndParse(); }
  bool Parse(const std::string& file, const std::map<std::string, std::string>& unsaved, SystemLayerCache& layers);
  void BuildPreamble(const clang::CompilerInvocation& invocation, const clang::PreambleBounds& bounds,
                     SystemLayerCache& layers);
  bool BuildPreambleOver(const clang::CompilerInvocation& invocation, const clang::PreambleBounds& bounds,
                         const SystemLayer* layer, SystemPrefix& prefix);
  llvm::IntrusiveRefCntPtr<llvm::vfs::FileSystem> Files() const {
    return layer ? layer->FileSystem() : llvm::vfs::getRealFileSystem();
  }
  void RecordWhatWasRead(const std::map<std::string, std::string>& unsaved);
  bool Unchanged(const std::string& file, const std::map<std::string, std::string>& unsaved) const;
  void EndParse() {
    if (action) action->EndSourceFile();
    action.reset();
    parsed.reset();
    mainBuffer.reset();
    unsavedBuffers.clear();
  }
};

AstCache::Handle::Handle(std::shared_ptr<Entry> entry) : m_entry(std::move(entry)), m_lock(m_entry->inUse) {}
AstCache::Handle::Handle(Handle&& other) noexcept : m_entry(std::move(other.m_entry)), m_lock(std::move(other.m_lock)) {}
AstCache::Handle::~Handle() = default;
ParsedFile* AstCache::Handle::ast() const { return m_entry->parsed.get(); }
clang::TextDiagnosticPrinter& AstCache::Handle::printer() const { return *m_entry->printer; }
const std::string& AstCache::Handle::diagnostics() const {
  m_entry->diagStream.flush();
  return m_entry->diagText;
}
bool AstCache::Handle::failed() const { return m_entry->failed || !m_entry->parsed; }

AstCache::AstCache(size_t capacity, LayerPreparation prepare)
    : m_capacity(std::max<size_t>(1, capacity)), m_prepare(prepare), m_layers(std::make_unique<SystemLayerCache>()) {}
AstCache::~AstCache() = default;

// Parses the file over its preamble, building (or rebuilding, when a header or the #include
// block changed) the preamble first. A preamble with errors is dropped, so that the parse reports
// them. Returns false when the file cannot be read or the compiler cannot be set up.
// Unsaved headers are remapped files: the preamble's reuse check compares their text (its hash), not
// a modification time that an editor's buffer does not have.
bool AstCache::Handle::Entry::Parse(const std::string& file, const std::map<std::string, std::string>& unsaved,
                                    SystemLayerCache& layers) {
  Entry& entry = *this;
  if (auto text = unsaved.find(file); text != unsaved.end()) {
    entry.mainBuffer = llvm::MemoryBuffer::getMemBufferCopy(text->second, file);
  } else {
    auto buffer = llvm::MemoryBuffer::getFile(file);
    if (!buffer) {
      entry.diagStream << "error: cannot read '" << file << "': " << buffer.getError().message() << "\n";
      return false;
    }
    entry.mainBuffer = std::move(*buffer);
  }
  auto invocation = std::make_shared<clang::CompilerInvocation>(*entry.invocation);
  for (auto& [path, text] : unsaved)
    if (path != file) {
      entry.unsavedBuffers.push_back(llvm::MemoryBuffer::getMemBufferCopy(text, path));
      invocation->getPreprocessorOpts().addRemappedFile(path, entry.unsavedBuffers.back().get());
    }
  invocation->getPreprocessorOpts().RetainRemappedFileBuffers = true;  // the entry owns the buffers
  auto bounds = clang::ComputePreambleBounds(invocation->getLangOpts(), *entry.mainBuffer, 0);
  if (!entry.preamble || (entry.layer && entry.layer->Stale()) ||
      !entry.preamble->CanReuse(*invocation, *entry.mainBuffer, bounds, *entry.Files()))
    entry.BuildPreamble(*invocation, bounds, layers);
  llvm::IntrusiveRefCntPtr<llvm::vfs::FileSystem> vfs = entry.Files();
  if (entry.preamble) {
    entry.preamble->AddImplicitPreamble(*invocation, vfs, entry.mainBuffer.get());
  } else {
    invocation->getPreprocessorOpts().addRemappedFile(file, entry.mainBuffer.get());
    if (entry.layer) invocation->getPreprocessorOpts().ImplicitPCHInclude = entry.layer->PchPath();
  }

  auto compiler = std::make_unique<clang::CompilerInstance>(std::make_shared<clang::PCHContainerOperations>());
  compiler->setInvocation(std::move(invocation));
  compiler->createDiagnostics(entry.printer.get(), /*ShouldOwnClient=*/false);
  compiler->createFileManager(vfs);
  if (!compiler->createTarget()) return false;
  entry.action = std::make_unique<clang::SyntaxOnlyAction>();
  if (!entry.action->BeginSourceFile(*compiler, compiler->getFrontendOpts().Inputs[0])) {
    entry.action.reset();
    return false;
  }
  IncludesSeen includes = entry.preamble || entry.layer ? entry.preambleIncludes : IncludesSeen{};
  includes.files.insert(file);
  compiler->getPreprocessor().addPPCallbacks(std::make_unique<IncludeRecorder>(compiler->getSourceManager(), includes));
  if (llvm::Error error = entry.action->Execute()) {
    entry.diagStream << "error: " << llvm::toString(std::move(error)) << "\n";
    entry.action->EndSourceFile();
    entry.action.reset();
    return false;
  }
  entry.parsed = std::make_unique<ParsedFile>(std::move(compiler), std::move(includes));
  return true;
}

// Builds the preamble over the system layer of the prefix that the last one-layer build found, and
// keeps it if its build finds the same prefix (SystemPrefix.h says why that makes it exact); else,
// or without a prefix, builds it in one layer and records the prefix for the next build.
void AstCache::Handle::Entry::BuildPreamble(const clang::CompilerInvocation& invocation,
                                            const clang::PreambleBounds& bounds, SystemLayerCache& layers) {
  preamble.reset();
  layer.reset();
  if (!prefix.includes.empty()) {
    if (auto over = layers.Get(flagsKey, *this->invocation, prefix)) {
      SystemPrefix seen;
      const bool built = BuildPreambleOver(invocation, bounds, over.get(), seen);
      if (seen == over->Prefix()) {
        // The layer fits. A preamble with errors is dropped, and the file is parsed over the layer
        // alone, which reports them.
        layer = std::move(over);
        builtOverLayer = built;
        if (!built) preambleIncludes = {};
        preambleIncludes.files.insert(layer->Headers().begin(), layer->Headers().end());
        return;
      }
      preamble.reset();
    }
  }
  SystemPrefix seen;
  if (!BuildPreambleOver(invocation, bounds, nullptr, seen)) return;
  // A layer that its own prefix does not fit is not tried again for this source.
  if (!prefix.includes.empty() && seen == prefix) layersRefused = true;
  prefix = layersRefused ? SystemPrefix{} : seen;
}

// One build of the preamble, over `layer` when there is one; `prefix` gets the system prefix the
// build saw. False when the build failed or had errors (then there is no preamble).
bool AstCache::Handle::Entry::BuildPreambleOver(const clang::CompilerInvocation& invocation,
                                                const clang::PreambleBounds& bounds, const SystemLayer* over,
                                                SystemPrefix& seen) {
  clang::CompilerInvocation preambleInvocation(invocation);
  preambleInvocation.getFrontendOpts().SkipFunctionBodies = true;  // as PreambleBodies decides
  if (over) preambleInvocation.getPreprocessorOpts().ImplicitPCHInclude = over->PchPath();
  clang::IgnoringDiagConsumer ignore;  // the parse without a preamble reports them
  auto diags = clang::CompilerInstance::createDiagnostics(diagOptions.get(), &ignore, /*ShouldOwnClient=*/false);
  preambleIncludes = {};
  PreambleBodies bodies(preambleIncludes, seen);
  auto built = clang::PrecompiledPreamble::Build(preambleInvocation, mainBuffer.get(), bounds, *diags,
                                                 over ? over->FileSystem() : llvm::vfs::getRealFileSystem(),
                                                 std::make_shared<clang::PCHContainerOperations>(),
                                                 /*StoreInMemory=*/true, /*StoragePath=*/"", bodies);
  if (!built || diags->hasErrorOccurred()) return false;
  preamble.emplace(std::move(*built));
  return true;
}

void AstCache::Handle::Entry::RecordWhatWasRead(const std::map<std::string, std::string>& unsaved) {
  reusable = false;
  parsedUnsaved = unsaved;
  parsedFiles.Clear();
  if (!parsed) return;
  for (const std::string& name : parsed->Includes().files)
    if (!unsaved.count(name) && !parsedFiles.Add(name)) return;  // cannot tell whether it changes: parse again next time
  reusable = true;
}

bool AstCache::Handle::Entry::Unchanged(const std::string& file, const std::map<std::string, std::string>& unsaved) const {
  if (!reusable || !parsed || failed || !mainBuffer || unsaved != parsedUnsaved) return false;
  if (auto text = unsaved.find(file); text != unsaved.end()) {
    if (text->second != mainBuffer->getBuffer()) return false;
  } else {
    auto buffer = llvm::MemoryBuffer::getFile(file);
    if (!buffer || (*buffer)->getBuffer() != mainBuffer->getBuffer()) return false;
  }
  return !parsedFiles.AnyChanged();
}

AstCache::Handle AstCache::Get(const std::string& file, const std::vector<std::string>& args,
                               const std::map<std::string, std::string>& unsaved) {
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
  if (entry->Unchanged(file, unsaved)) {
    // The same text and headers as the last parse: its AST serves as it is, with its diagnostics
    // engine cleared of what the last translation reported.
    entry->printer->clear();
    entry->printer->errors = 0;
    entry->parsed->getDiagnostics().Reset(/*soft=*/true);
    std::lock_guard<std::mutex> guard(m_mutex);
    ++m_reparses;
    ++m_reuses;
    return handle;
  }
  // Decided under the entry's lock: another request may have parsed it meanwhile. A file whose last
  // parse failed starts again from its arguments.
  const bool reparse = entry->parsed && !entry->failed;
  entry->EndParse();
  if (!reparse) {
    entry->preamble.reset();
    entry->diagOptions = new clang::DiagnosticOptions();
    entry->diagOptions->ShowColors = false;
    entry->printer = std::make_unique<ErrorCountingPrinter>(entry->diagStream, entry->diagOptions.get());
    std::vector<const char*> argv = {"clang++"};
    for (auto& a : args) argv.push_back(a.c_str());
    argv.push_back(file.c_str());
    clang::CreateInvocationOptions options;
    options.Diags = clang::CompilerInstance::createDiagnostics(entry->diagOptions.get(), entry->printer.get(), false);
    entry->invocation = clang::createInvocation(argv, options);
    entry->flagsKey = key.substr(file.size());
    if (entry->invocation) entry->invocation->getHeaderSearchOpts().ResourceDir = CROSSRT_CLANG_RESOURCE_DIR;
  }
  entry->printer->clear();
  entry->printer->errors = 0;
  entry->failed = !entry->invocation || !entry->Parse(file, unsaved, *m_layers) || entry->printer->errors > 0;
  entry->RecordWhatWasRead(unsaved);
  const bool prepare = m_prepare == LayerPreparation::AfterParse || (m_prepare == LayerPreparation::AfterReparse && reparse);
  if (prepare && !entry->layer && !entry->prefix.includes.empty())
    m_layers->Prepare(entry->flagsKey, std::make_shared<const clang::CompilerInvocation>(*entry->invocation), entry->prefix);
  std::lock_guard<std::mutex> guard(m_mutex);
  ++(reparse ? m_reparses : m_parses);
  if (entry->builtOverLayer) ++m_layeredPreambles;
  entry->builtOverLayer = false;
  return handle;
}

AstCacheStats AstCache::Stats() const {
  std::lock_guard<std::mutex> guard(m_mutex);
  return {m_entries.size(), m_capacity, m_parses, m_reparses, m_reuses, m_layers->Builds(), m_layeredPreambles};
}

}  // namespace crossrt::engine
