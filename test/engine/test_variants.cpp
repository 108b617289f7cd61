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
    CHECK(host.find(Squeezed(std::string("m_pipelines.") + pipeline + " = crossrt::ComputePipeline(")) != std::string::npos);
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
