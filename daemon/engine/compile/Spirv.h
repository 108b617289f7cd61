// GLSL to SPIR-V in-process with the glslang library, a cache of compiled shaders by their text,
// and the C++ source that embeds the words in the generated class.
#pragma once
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace crossrt::engine {

// Compiles one GLSL shader of `stage` (comp, rgen, rcall, rint, rchit or rmiss) to SPIR-V (as
// `glslangValidator -V --target-env vulkan1.2` would); returns the words or throws.
std::vector<uint32_t> CompileGlsl(const std::string& name, const std::string& glsl, const std::string& stage);

// The <Class>_Vulkan_shaders.cpp that holds each shader's words as <Class>_<shader>_spv.
std::string EmbedSpirv(const std::string& className, const std::vector<std::pair<std::string, std::vector<uint32_t>>>& shaders);

// SPIR-V of GLSL sources already compiled, by content: an edit recompiles only the shaders whose
// text changed. The daemon keeps one for its lifetime.
class SpirvCache {
public:
  bool Find(const std::string& glsl, std::vector<uint32_t>& words) const;
  void Add(const std::string& glsl, const std::vector<uint32_t>& words);
  size_t Size() const;

private:
  mutable std::mutex m_mutex;
  std::map<std::string, std::vector<uint32_t>> m_byGlsl;
};

}  // namespace crossrt::engine
