// The size and modification time of files read, to tell later whether any of them changed: the AST
// cache's "nothing it read has changed" check and a system layer's staleness.
#pragma once
#include <llvm/Support/Chrono.h>
#include <llvm/Support/FileSystem.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace crossrt::engine {

class FileStamps {
public:
  // Stamps `name` as it is now; false when it cannot be read (then nothing can tell whether it changes).
  bool Add(const std::string& name) {
    llvm::sys::fs::file_status status;
    if (llvm::sys::fs::status(name, status)) return false;
    m_stamps.push_back({name, {status.getSize(), status.getLastModificationTime()}});
    return true;
  }
  void Clear() { m_stamps.clear(); }
  // A stamped file changed size or time, or cannot be read any more.
  bool AnyChanged() const {
    for (auto& [name, seen] : m_stamps) {
      llvm::sys::fs::file_status status;
      if (llvm::sys::fs::status(name, status) || status.getSize() != seen.first || status.getLastModificationTime() != seen.second)
        return true;
    }
    return false;
  }

private:
  std::vector<std::pair<std::string, std::pair<uint64_t, llvm::sys::TimePoint<>>>> m_stamps;
};

}  // namespace crossrt::engine
