#include "Outputs.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace crossrt::client {

std::vector<std::string> WriteOutputs(const engine::TranslateRequest& request, const engine::TranslateResult& result) {
  std::vector<std::string> written;
  for (auto& [name, contents] : result.files) {
    fs::path path = fs::path(request.outputDir) / name;
    std::error_code ec;
    if (fs::exists(path, ec)) {
      std::ifstream in(path, std::ios::binary);
      std::ostringstream old;
      old << in.rdbuf();
      if (old.str() == contents) continue;  // same bytes: keep the timestamp
    }
    fs::create_directories(path.parent_path(), ec);
    if (ec) throw std::runtime_error("cannot create directory '" + path.parent_path().string() + "': " + ec.message());
    fs::path tmp = path;
    tmp += ".tmp";
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      out << contents;
      if (!out.good()) throw std::runtime_error("cannot write '" + tmp.string() + "'");
    }
    fs::rename(tmp, path, ec);
    if (ec) throw std::runtime_error("cannot rename '" + tmp.string() + "' to '" + path.string() + "': " + ec.message());
    written.push_back(name);
  }
  return written;
}

}  // namespace crossrt::client
