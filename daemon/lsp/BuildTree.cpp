// Finds the build trees and the class requests recorded in them (BuildTree.h).
#include "BuildTree.h"

#include "Protocol.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace crossrt::lsp {

std::string RealPath(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  return ec ? fs::path(path).lexically_normal().string() : p.string();
}

std::vector<std::string> FindBuildTrees(const std::string& workspace) {
  std::vector<std::string> trees;
  std::error_code ec;
  if (workspace.empty() || !fs::is_directory(workspace, ec)) return trees;
  if (fs::exists(fs::path(workspace) / "CMakeCache.txt", ec)) trees.push_back(RealPath(workspace));
  for (auto it = fs::directory_iterator(workspace, ec); !ec && it != fs::directory_iterator(); it.increment(ec))
    if (it->is_directory(ec) && fs::exists(it->path() / "CMakeCache.txt", ec)) trees.push_back(RealPath(it->path().string()));
  std::sort(trees.begin(), trees.end());
  trees.erase(std::unique(trees.begin(), trees.end()), trees.end());
  return trees;
}

namespace {

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read it");
  return nlohmann::json::parse(in);
}

}  // namespace

std::vector<ClassRequest> FindClassRequests(const std::vector<std::string>& buildTrees, std::string& problems) {
  std::vector<ClassRequest> found;
  std::set<std::string> keys;
  for (const std::string& tree : buildTrees) {
    std::error_code ec;
    std::vector<fs::path> records;
    for (fs::directory_iterator it(fs::path(tree) / ".crossrt" / "requests", ec), end; !ec && it != end; it.increment(ec))
      if (it->path().extension() == ".json") records.push_back(it->path());
    std::sort(records.begin(), records.end());
    for (const fs::path& record : records) {
      ClassRequest c;
      try {
        c.request = protocol::RequestFromJson(ReadJson(record));
      } catch (const std::exception& e) {
        problems += record.string() + ": " + e.what() + "\n";
        continue;
      }
      c.key = RealPath(c.request.outputDir);
      if (!keys.insert(c.key).second) continue;
      for (auto& s : c.request.sources) c.inputs.insert(RealPath(s));
      try {  // what the last translation read: the class's headers among them
        const nlohmann::json manifest = ReadJson(fs::path(c.request.outputDir) / ".crossrt-manifest.json");
        for (auto& input : manifest.at("inputs")) c.inputs.insert(input.at(0).get<std::string>());
      } catch (const std::exception&) {
        // none yet: the class never translated; its sources are enough to start
      }
      found.push_back(std::move(c));
    }
  }
  // Vulkan's rules are the strictest: an edit's errors show soonest when its translations go first.
  auto rank = [](const ClassRequest& c) { return c.request.backend == engine::Backend::Vulkan ? 0 : c.request.backend == engine::Backend::Ispc ? 1 : 2; };
  std::sort(found.begin(), found.end(), [&](const ClassRequest& a, const ClassRequest& b) {
    return rank(a) != rank(b) ? rank(a) < rank(b) : a.key < b.key;
  });
  return found;
}

}  // namespace crossrt::lsp
