// Builds and keeps the system headers' layers of preambles (SystemLayer.h says what one is): a PCH
// of a header that includes the prefix, written into memory with Clang's PCH generator.
#include "parse/SystemLayer.h"

#include <clang/Basic/Diagnostic.h>
#include <clang/Frontend/CompilerInstance.h>
#include <clang/Frontend/CompilerInvocation.h>
#include <clang/Frontend/FrontendActions.h>
#include <clang/Lex/PPCallbacks.h>
#include <clang/Lex/Preprocessor.h>
#include <clang/Lex/PreprocessorOptions.h>
#include <clang/Serialization/ASTWriter.h>
#include <clang/Serialization/PCHContainerOperations.h>
#include <llvm/Support/MemoryBuffer.h>
#include <llvm/Support/VirtualFileSystem.h>

#include <atomic>

namespace crossrt::engine {

namespace {

// A PCH generated into a buffer rather than a file.
class LayerAction : public clang::GeneratePCHAction {
public:
  explicit LayerAction(std::shared_ptr<clang::PCHBuffer> buffer) : m_buffer(std::move(buffer)) {}

protected:
  std::unique_ptr<clang::ASTConsumer> CreateASTConsumer(clang::CompilerInstance& compiler, llvm::StringRef) override {
    std::string sysroot;
    if (!ComputeASTConsumerArguments(compiler, sysroot)) return nullptr;
    if (!compiler.getFrontendOpts().RelocatablePCH) sysroot.clear();
    return std::make_unique<clang::PCHGenerator>(compiler.getPreprocessor(), compiler.getModuleCache(), "", sysroot,
                                                 m_buffer, llvm::ArrayRef<std::shared_ptr<clang::ModuleFileExtension>>());
  }

private:
  std::shared_ptr<clang::PCHBuffer> m_buffer;
};

// The headers the layer's build reads; a user's among them makes the layer unusable (the layer
// skips every function body, and the user's edits to it would go unseen).
class LayerHeaders : public clang::PPCallbacks {
public:
  LayerHeaders(std::set<std::string>& headers, bool& readUserFile) : m_headers(headers), m_readUserFile(readUserFile) {}
  void InclusionDirective(clang::SourceLocation, const clang::Token&, llvm::StringRef, bool, clang::CharSourceRange,
                          clang::OptionalFileEntryRef file, llvm::StringRef, llvm::StringRef, const clang::Module*, bool,
                          clang::SrcMgr::CharacteristicKind kind) override {
    if (!file) return;
    m_headers.insert(file->getName().str());
    if (!clang::SrcMgr::isSystem(kind)) m_readUserFile = true;
  }

private:
  std::set<std::string>& m_headers;
  bool& m_readUserFile;
};

}  // namespace

std::shared_ptr<const SystemLayer> SystemLayer::Build(const clang::CompilerInvocation& base, const SystemPrefix& prefix) {
  static std::atomic<uint64_t> serial{0};
  const std::string folder = "/__crossrt_system_layer__/" + std::to_string(++serial);
  const std::string header = folder + "/prefix.h";
  std::string text = "// The system headers that the preamble over this layer starts with.\n";
  for (const std::string& name : prefix.includes) text += "#include <" + name + ">\n";
  auto memory = llvm::makeIntrusiveRefCnt<llvm::vfs::InMemoryFileSystem>();
  memory->addFile(header, 0, llvm::MemoryBuffer::getMemBufferCopy(text, header));
  auto files = llvm::makeIntrusiveRefCnt<llvm::vfs::OverlayFileSystem>(llvm::vfs::getRealFileSystem());
  files->pushOverlay(memory);

  auto invocation = std::make_shared<clang::CompilerInvocation>(base);
  clang::FrontendOptions& frontend = invocation->getFrontendOpts();
  const clang::InputKind kind = frontend.Inputs.empty() ? clang::InputKind(clang::Language::CXX) : frontend.Inputs[0].getKind();
  frontend.Inputs = {clang::FrontendInputFile(header, kind)};
  frontend.ProgramAction = clang::frontend::GeneratePCH;
  frontend.SkipFunctionBodies = true;
  frontend.OutputFile.clear();
  invocation->getPreprocessorOpts().ImplicitPCHInclude.clear();
  invocation->getPreprocessorOpts().clearRemappedFiles();

  clang::IgnoringDiagConsumer ignore;  // a prefix that does not compile alone gets no layer
  clang::CompilerInstance compiler(std::make_shared<clang::PCHContainerOperations>());
  compiler.setInvocation(invocation);
  compiler.createDiagnostics(&ignore, /*ShouldOwnClient=*/false);
  compiler.createFileManager(files);
  if (!compiler.createTarget()) return nullptr;
  auto pch = std::make_shared<clang::PCHBuffer>();
  LayerAction action(pch);
  if (!action.BeginSourceFile(compiler, frontend.Inputs[0])) return nullptr;
  auto layer = std::shared_ptr<SystemLayer>(new SystemLayer());
  bool readUserFile = false;
  compiler.getPreprocessor().addPPCallbacks(std::make_unique<LayerHeaders>(layer->m_headers, readUserFile));
  llvm::Error error = action.Execute();
  action.EndSourceFile();
  if (error) {
    llvm::consumeError(std::move(error));
    return nullptr;
  }
  if (compiler.getDiagnostics().hasErrorOccurred() || !pch->IsComplete || readUserFile) return nullptr;

  layer->m_prefix = prefix;
  layer->m_pchPath = folder + "/prefix.pch";
  memory->addFile(layer->m_pchPath, 0,
                  llvm::MemoryBuffer::getMemBufferCopy(llvm::StringRef(pch->Data.data(), pch->Data.size()), layer->m_pchPath));
  layer->m_files = files;
  for (const std::string& name : layer->m_headers)
    if (!layer->m_headerStamps.Add(name)) return nullptr;  // cannot tell when it changes
  return layer;
}

llvm::IntrusiveRefCntPtr<llvm::vfs::FileSystem> SystemLayer::FileSystem() const { return m_files; }

bool SystemLayer::Stale() const { return m_headerStamps.AnyChanged(); }

SystemLayerCache::~SystemLayerCache() {
  std::lock_guard<std::mutex> guard(m_backgroundMutex);
  for (std::thread& build : m_background) build.join();
}

std::string SystemLayerCache::Key(const std::string& flagsKey, const SystemPrefix& prefix) {
  std::string key = flagsKey;
  for (const std::string& name : prefix.includes) key += '\x1e' + name;
  return key;
}

std::shared_ptr<const SystemLayer> SystemLayerCache::Cached(const std::string& key) {
  for (auto it = m_layers.begin(); it != m_layers.end(); ++it) {
    if (it->first != key) continue;
    if (it->second->Stale()) {
      m_layers.erase(it);
      return nullptr;
    }
    m_layers.splice(m_layers.begin(), m_layers, it);
    return m_layers.front().second;
  }
  return nullptr;
}

std::shared_ptr<const SystemLayer> SystemLayerCache::Get(const std::string& flagsKey, const clang::CompilerInvocation& base,
                                                         const SystemPrefix& prefix) {
  const std::string key = Key(flagsKey, prefix);
  std::lock_guard<std::mutex> guard(m_mutex);  // one build at a time: a second asker waits for the first's layer
  if (auto layer = Cached(key)) return layer;
  if (m_refused.count(key)) return nullptr;
  std::shared_ptr<const SystemLayer> layer = SystemLayer::Build(base, prefix);
  ++m_builds;
  if (!layer) {
    m_refused.insert(key);  // not tried again: such a source keeps the one-layer preamble
    return nullptr;
  }
  m_layers.emplace_front(key, layer);
  if (m_layers.size() > m_capacity) m_layers.pop_back();
  return layer;
}

void SystemLayerCache::Prepare(const std::string& flagsKey, std::shared_ptr<const clang::CompilerInvocation> base,
                               const SystemPrefix& prefix) {
  {
    std::unique_lock<std::mutex> lock(m_mutex, std::try_to_lock);
    if (!lock.owns_lock()) return;  // a build is under way
    const std::string key = Key(flagsKey, prefix);
    if (m_refused.count(key) || Cached(key)) return;
  }
  std::lock_guard<std::mutex> guard(m_backgroundMutex);
  m_background.emplace_back([this, flagsKey, base = std::move(base), prefix] { Get(flagsKey, *base, prefix); });
}

uint64_t SystemLayerCache::Builds() const {
  std::lock_guard<std::mutex> guard(m_mutex);
  return m_builds;
}

}  // namespace crossrt::engine
