// The classes a build tree translates, as the language server learns them: every
// crossrt_add_class records its request in <build tree>/.crossrt/requests/ when the build translates
// it (client/Manifest.h), and the manifest in its output folder lists the files the last successful
// translation read.
//
// Build trees are named (--build-dir, the client's initializationOptions.buildDirectory) or found
// under the workspace's folders as clangd finds compile_commands.json: the folder itself and its
// direct subfolders that hold a CMakeCache.txt.
#pragma once
#include "TranslateTypes.h"

#include <set>
#include <string>
#include <vector>

namespace crossrt::lsp {

struct ClassRequest {
  std::string key;                       // what tells one translation from another (its output folder)
  engine::TranslateRequest request;
  std::set<std::string> inputs;          // the sources, and what the last build's translation read
};

// Build trees under `workspace` (absolute path), or none.
std::vector<std::string> FindBuildTrees(const std::string& workspace);

// Every recorded request under the build trees: Vulkan's, then ISPC's, then the CPU's (the order the
// server translates them in), each by output folder. Unreadable records are skipped with a line in
// `problems`.
std::vector<ClassRequest> FindClassRequests(const std::vector<std::string>& buildTrees, std::string& problems);

// `path` made absolute and normal, with symbolic links followed where it exists.
std::string RealPath(const std::string& path);

}  // namespace crossrt::lsp
