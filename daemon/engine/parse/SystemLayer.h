// The system headers' layer of a preamble: a PCH of a source's system prefix (SystemPrefix.h), built
// once and shared by every source parsed with the same flags and the same prefix.
//
// The layer lives in memory, in a file system of its own laid over the real one: a header that
// includes the prefix, and the PCH built from it. A preamble built with the layer as its implicit
// PCH is a chained PCH over it, and names it by that path; a parse over such a preamble reads both
// through the layer's file system. Like the preamble, the layer skips the bodies of functions (all
// of them are in system headers).
#pragma once
#include "parse/FileStamps.h"
#include "parse/SystemPrefix.h"

#include <llvm/ADT/IntrusiveRefCntPtr.h>

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace clang {
class CompilerInvocation;
}
namespace llvm::vfs {
class FileSystem;
}

namespace crossrt::engine {

class SystemLayer {
public:
  // Builds the layer of `prefix` with the flags of `base` (a source's invocation). Null when the
  // prefix does not compile on its own or reads a user's file.
  static std::shared_ptr<const SystemLayer> Build(const clang::CompilerInvocation& base, const SystemPrefix& prefix);

  const SystemPrefix& Prefix() const { return m_prefix; }
  const std::string& PchPath() const { return m_pchPath; }           // the implicit PCH to build over
  llvm::IntrusiveRefCntPtr<llvm::vfs::FileSystem> FileSystem() const;  // the real one, with the layer's files
  const std::set<std::string>& Headers() const { return m_headers; }  // every header it read
  bool Stale() const;  // a header it read has changed on disk since

private:
  SystemPrefix m_prefix;
  std::string m_pchPath;
  llvm::IntrusiveRefCntPtr<llvm::vfs::FileSystem> m_files;
  std::set<std::string> m_headers;
  FileStamps m_headerStamps;
};

// The layers built so far, shared between the AST cache's entries; the least recently used is
// dropped past `capacity` (an entry that uses it keeps it alive).
class SystemLayerCache {
public:
  explicit SystemLayerCache(size_t capacity = 4) : m_capacity(capacity) {}
  ~SystemLayerCache();  // waits for the layers being built in the background
  // The layer for these flags (`flagsKey` names them) and this prefix: the cached one unless a
  // header it read changed, else a new one. Null when it cannot be built (and not tried again).
  std::shared_ptr<const SystemLayer> Get(const std::string& flagsKey, const clang::CompilerInvocation& base,
                                         const SystemPrefix& prefix);
  // Starts building that layer on a thread of its own, unless it is cached, refused or a build is
  // under way; never waits. A Get for it meanwhile waits for that build.
  void Prepare(const std::string& flagsKey, std::shared_ptr<const clang::CompilerInvocation> base,
               const SystemPrefix& prefix);
  uint64_t Builds() const;

private:
  static std::string Key(const std::string& flagsKey, const SystemPrefix& prefix);
  std::shared_ptr<const SystemLayer> Cached(const std::string& key);  // with m_mutex held

  std::mutex m_backgroundMutex;
  std::vector<std::thread> m_background;
  mutable std::mutex m_mutex;
  size_t m_capacity;
  uint64_t m_builds = 0;
  std::list<std::pair<std::string, std::shared_ptr<const SystemLayer>>> m_layers;  // most recently used first
  std::set<std::string> m_refused;  // keys whose layer could not be built
};

}  // namespace crossrt::engine
