// A kernel's shaders (ShaderCode.cpp, CodeGenSupport.cpp): the one every device runs, a reduction
// pass for member reductions, one-thread Start and Finish shaders for the statements around the
// loop nest, and a pipeline for each in the host code. Kernels without those get none of them.
#include "EngineSupport.h"

#include <set>

using namespace crossrt::engine;

namespace {

const char* kHeader = R"(#pragma once
#include <vector>
class Phases
{
public:
  virtual ~Phases() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* data);
protected:
  void kernel1D_Plain(int n, float* data);
  void kernel1D_Sum(int n, const float* data);
  void kernel1D_Mean(int n, const float* data);
  float m_total = 0.0f, m_sum = 0.0f, m_mean = 0.0f;
};
)";

const char* kSource = R"(#include "Phases.h"
void Phases::Run(int n, float* data)
{
  kernel1D_Plain(n, data);
  kernel1D_Sum(n, data);
  kernel1D_Mean(n, data);
}
void Phases::kernel1D_Plain(int n, float* data)
{
  for (int i = 0; i < n; ++i) data[i] = 2.0f * data[i];
}
void Phases::kernel1D_Sum(int n, const float* data)
{
  for (int i = 0; i < n; ++i) m_total += data[i];
}
void Phases::kernel1D_Mean(int n, const float* data)
{
  m_sum = 0.0f;
  for (int i = 0; i < n; ++i) m_sum += data[i];
  m_mean = m_sum / float(n > 0 ? n : 1);
}
)";

}  // namespace

TEST_CASE("Variants: each kernel gets the shaders its body needs, and a pipeline for each", "[engine][variants]")
{
  TempClass tc("Phases", kHeader, kSource);
  const TranslateResult r = Translate(MakeRequest(tc, "Phases"));
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  std::set<std::string> shaders;
  for (auto& [name, text] : r.files)
    if (name.rfind("shaders/", 0) == 0) shaders.insert(name.substr(8));
  const std::set<std::string> expected = {"kernel1D_Plain.comp",
                                          "kernel1D_Sum.comp",  "kernel1D_Sum_Reduce.comp",
                                          "kernel1D_Mean.comp", "kernel1D_Mean_Start.comp", "kernel1D_Mean_Finish.comp", "kernel1D_Mean_Reduce.comp"};
  CHECK(shaders == expected);
  const std::string host = Squeezed(r.files.at("Phases_Vulkan.cpp"));
  for (const char* pipeline : {"kernel1D_Plain", "kernel1D_Sum", "kernel1D_Sum_Reduce", "kernel1D_Mean", "kernel1D_Mean_Start",
                               "kernel1D_Mean_Finish", "kernel1D_Mean_Reduce"})
  {
    INFO(pipeline);
    CHECK(host.find(Squeezed(std::string("crt_pipelines.") + pipeline + " = crossrt::ComputePipeline(")) != std::string::npos);
  }
  // The embedded SPIR-V holds one array per shader.
  const std::string& spirv = r.files.at("Phases_Vulkan_shaders.cpp");
  for (auto& shader : expected)
  {
    INFO(shader);
    CHECK(spirv.find("const uint32_t Phases_" + shader.substr(0, shader.size() - 5) + "_spv[] = {") != std::string::npos);
  }
}

TEST_CASE("Variants: the CPU class has no shaders", "[engine][variants]")
{
  TempClass tc("Phases", kHeader, kSource);
  const TranslateResult r = Translate(MakeRequest(tc, "Phases", Backend::Cpu));
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  for (auto& [name, text] : r.files) CHECK(name.rfind("shaders/", 0) != 0);
  CHECK(r.files.count("Phases_CPU.cpp") == 1);
  CHECK(r.files.count("Phases_CPU.h") == 1);
}

namespace {

// A renderer as a user writes one: materials behind a virtual interface, textures they name in an
// array of textures, which the kernel samples before it calls the material (PathTracer's shape).
const char* kTexturedHeader = R"(#pragma once
#include "Image2D.h"
#include "LiteMath.h"
#include <cstdint>
#include <memory>
#include <vector>
struct IShader
{
  virtual ~IShader() = default;
  virtual int TextureId() const { return -1; }
  virtual LiteMath::float4 Shade(LiteMath::float4 texel) const = 0;
};
struct Tinted : IShader
{
  LiteMath::float4 tint = LiteMath::float4(1.0f);
  int texture = 0;
  int TextureId() const override { return texture; }
  LiteMath::float4 Shade(LiteMath::float4 texel) const override { return texel * tint; }
};
struct Flat : IShader
{
  LiteMath::float4 color = LiteMath::float4(0.5f);
  LiteMath::float4 Shade(LiteMath::float4) const override { return color; }
};
class TexturedShading
{
public:
  virtual ~TexturedShading() = default;
  virtual void Run(int n, [[crossrt::size("n")]] const uint32_t* ids, [[crossrt::size("n")]] const LiteMath::float2* uvs,
                   [[crossrt::size("n")]] LiteMath::float4* out);
  virtual void CommitDeviceData() {}
  std::vector<std::shared_ptr<IShader>> m_shaders;
  std::vector<LiteImage::Texture2D<LiteMath::float4>> m_textures;
protected:
  void kernel1D_Run(int n, const uint32_t* ids, const LiteMath::float2* uvs, LiteMath::float4* out);
};
)";

const char* kTexturedSource = R"(#include "TexturedShading.h"
void TexturedShading::Run(int n, const uint32_t* ids, const LiteMath::float2* uvs, LiteMath::float4* out) { kernel1D_Run(n, ids, uvs, out); }
void TexturedShading::kernel1D_Run(int n, const uint32_t* ids, const LiteMath::float2* uvs, LiteMath::float4* out)
{
  for (int i = 0; i < n; ++i)
  {
    const int texture = m_shaders[ids[i]]->TextureId();
    const LiteMath::float4 texel = texture < 0 ? LiteMath::float4(1.0f) : m_textures[texture].sample(uvs[i]);
    out[i] = m_shaders[ids[i]]->Shade(texel);
  }
}
)";

}  // namespace

TEST_CASE("Variants: at level 3 a kernel that samples arrays of textures runs its virtual calls as callables, sampling on the GPU's samplers",
          "[engine][variants][virtual]")
{
  TempClass tc("TexturedShading", kTexturedHeader, kTexturedSource);
  TranslateRequest request = MakeRequest(tc, "TexturedShading");
  request.compileArgs.push_back("-I" CROSSRT_SOURCE_DIR "/libs/liteimage");
  request.virtualLevel = 3;
  const TranslateResult r = Translate(request);
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  // The ray generation shader, the textures form of the compute shader, and the fallback of every device.
  for (const char* shader : {"kernel1D_Run_Callables_Textures.rgen", "kernel1D_Run_Textures.comp", "kernel1D_Run.comp",
                             "m_shaders_Tinted_Shade.rcall", "m_shaders_Flat_Shade.rcall", "m_shaders_Flat_TextureId.rcall"})
  {
    INFO(shader);
    CHECK(r.files.count(std::string("shaders/") + shader) == 1);
  }
  const std::string& rgen = r.files.at("shaders/kernel1D_Run_Callables_Textures.rgen");
  CHECK(rgen.find("uniform sampler2D m_textures[]") != std::string::npos);  // sampled with the GPU's samplers
  CHECK(rgen.find("executeCallableEXT(") != std::string::npos);
  CHECK(rgen.find("Tinted_Shade(") == std::string::npos);  // the classes' code is in the callables, not here
  CHECK(r.files.at("shaders/kernel1D_Run.comp").find("Tinted_Shade(") != std::string::npos);  // the level-2 switch calls it
  // The host creates it with its texture set where the device has both, tries it first, and binds the array.
  const std::string host = Squeezed(r.files.at("TexturedShading_Vulkan.cpp"));
  CHECK(host.find(Squeezed("if (crt_ctx->hasRayTracingPipeline && crt_ctx->hasTextureArrays)")) != std::string::npos);
  // with the specialization the other pipelines get (the classes the objects hold)
  CHECK(host.find(Squeezed("\"TexturedShading::kernel1D_Run_Callables_Textures\", 1, crt_pipelineConstants);")) != std::string::npos);
  CHECK(host.find(Squeezed("if (crt_useRayTracingPipelines && crt_useTextureHardware)")) != std::string::npos);
  CHECK(host.find(Squeezed("crt_pipelines.kernel1D_Run_Callables_Textures.BindTextureArrays(crt_cmd, {&crt_textureArrays.m_textures});")) !=
        std::string::npos);
  CHECK(host.find("still switches over the objects' classes") == std::string::npos);
}
