// No fused multiply-adds the CPU does not do (NoContraction.cpp): every float multiply, add,
// divide and negate of a generated shader carries NoContraction, the module stays valid, and a
// class compiled with -ffp-contract=fast or -ffast-math lets the GPU fuse them.
#include "EngineSupport.h"
#include "compile/NoContraction.h"
#include "compile/Spirv.h"

#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

using namespace crossrt::engine;

namespace {

constexpr uint32_t kOpDecorate = 71, kNoContraction = 42;

struct Census {
  std::set<uint32_t> arithmetic;  // results of float arithmetic
  std::multiset<uint32_t> noContraction;  // ids decorated NoContraction, with repeats
};

Census Count(const std::vector<uint32_t>& words)
{
  static const std::set<uint32_t> arithmeticOps = {127, 129, 131, 133, 136, 142, 143, 144, 145, 146, 147, 148};
  Census c;
  for (size_t at = 5; at < words.size(); at += words[at] >> 16)
  {
    const uint32_t opcode = words[at] & 0xffffu;
    if (arithmeticOps.count(opcode)) c.arithmetic.insert(words[at + 2]);
    if (opcode == kOpDecorate && words[at + 2] == kNoContraction) c.noContraction.insert(words[at + 1]);
  }
  return c;
}

// The words of one array of a generated _Vulkan_shaders.cpp.
std::vector<uint32_t> EmbeddedWords(const std::string& text, const std::string& array)
{
  const size_t start = text.find("const uint32_t " + array + "[] = {");
  REQUIRE(start != std::string::npos);
  std::istringstream in(text.substr(text.find('{', start) + 1, text.find("};", start) - text.find('{', start) - 1));
  std::vector<uint32_t> words;
  for (std::string token; in >> token;) words.push_back(uint32_t(std::stoul(token, nullptr, 16)));
  return words;
}

const char* kShader = R"(#version 460
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Data { vec4 v[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  vec3 a = v[i].xyz, b = v[i + 1u].xyz;
  float edge = a.x * b.y - a.y * b.x;          // the watertight test's edge function
  vec3 scaled = a * v[i].w + b;                 // vector times scalar, plus
  v[i] = vec4(scaled / edge, -dot(a, b));
}
)";

const char* kHeader = R"(#pragma once
class Edges
{
public:
  virtual ~Edges() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* data);
protected:
  void kernel1D_Edge(int n, float* data);
};
)";

const char* kSource = R"(#include "Edges.h"
void Edges::Run(int n, float* data) { kernel1D_Edge(n, data); }
void Edges::kernel1D_Edge(int n, float* data)
{
  for (int i = 0; i < n / 4; ++i) data[4 * i] = data[4 * i] * data[4 * i + 1] - data[4 * i + 2] * data[4 * i + 3];
}
)";

}  // namespace

TEST_CASE("NoContraction: every float arithmetic result is decorated once, and the module stays valid", "[engine][spirv]")
{
  std::vector<uint32_t> words = CompileGlsl("edges", kShader, "comp");
  const Census before = Count(words);
  REQUIRE(before.arithmetic.size() >= 6);  // two products, a difference, a vector product and sum, a quotient, a dot, a negation
  CHECK(before.noContraction.empty());

  CHECK(ForbidContraction(words) == before.arithmetic.size());
  const Census after = Count(words);
  CHECK(after.arithmetic == before.arithmetic);  // nothing renumbered
  for (uint32_t id : after.arithmetic) CHECK(after.noContraction.count(id) == 1);
  CHECK(after.noContraction.size() == after.arithmetic.size());
  CHECK(ForbidContraction(words) == 0);  // already decorated: nothing twice

  // spirv-val accepts the decorated module: the decorations sit among the other annotations.
  const fs::path file = fs::temp_directory_path() / "crossrt_no_contraction.spv";
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(words.data()), std::streamsize(words.size() * 4));
  CHECK(std::system(("spirv-val --target-env vulkan1.2 " + file.string()).c_str()) == 0);
  fs::remove(file);

  std::vector<uint32_t> notSpirv = {1, 2, 3, 4, 5, 6};
  CHECK_THROWS_WITH(ForbidContraction(notSpirv), Catch::Contains("not SPIR-V"));
  std::vector<uint32_t> truncated(words.begin(), words.begin() + 8);  // the header, OpCapability Shader, one more
  REQUIRE(truncated[5] == ((2u << 16) | 17u));
  truncated[7] = (40u << 16) | 17u;  // an instruction claiming more words than there are
  CHECK_THROWS_WITH(ForbidContraction(truncated), Catch::Contains("runs past the end"));
}

TEST_CASE("NoContraction: the class's flags decide, the last one winning", "[engine][spirv]")
{
  CHECK_FALSE(AllowsContraction({}));
  CHECK_FALSE(AllowsContraction({"-O3", "-march=native"}));  // GCC would fuse with FMA units; the GPU keeps C++'s roundings
  CHECK(AllowsContraction({"-ffast-math"}));
  CHECK(AllowsContraction({"-ffp-contract=fast"}));
  CHECK_FALSE(AllowsContraction({"-ffast-math", "-fno-fast-math"}));
  CHECK_FALSE(AllowsContraction({"-ffp-contract=fast", "-ffp-contract=off"}));
  CHECK(AllowsContraction({"-ffp-contract=on", "-ffp-contract=fast"}));

  // Through a translation: the same kernel's SPIR-V with and without the decorations.
  TempClass tc("Edges", kHeader, kSource);
  TranslateRequest request = MakeRequest(tc, "Edges");
  const TranslateResult exact = Translate(request);
  INFO(exact.diagnostics);
  REQUIRE(exact.ok);
  request.compileArgs.push_back("-ffp-contract=fast");
  const TranslateResult fused = Translate(request);
  REQUIRE(fused.ok);
  const Census e = Count(EmbeddedWords(exact.files.at("Edges_Vulkan_shaders.cpp"), "Edges_kernel1D_Edge_spv"));
  const Census f = Count(EmbeddedWords(fused.files.at("Edges_Vulkan_shaders.cpp"), "Edges_kernel1D_Edge_spv"));
  REQUIRE(e.arithmetic.size() >= 3);
  CHECK(e.noContraction.size() == e.arithmetic.size());
  CHECK(f.noContraction.empty());
  CHECK(f.arithmetic.size() == e.arithmetic.size());
}
