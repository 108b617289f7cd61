// Memory layouts (GlslTypes.cpp): a std::vector member's elements get a std430 buffer where std430
// reproduces their C++ layout, a scalar one where only that does, and a diagnostic where neither
// does; plain members join the class data at their std430 alignment. The expected layouts follow
// the GLSL rules (std430: vec3 aligned to 16 bytes; scalar: to its component) and LiteMath's C++
// types (float3 is 12 bytes aligned to 4, float2 aligned to 8, float4 to 16).
#include "EngineSupport.h"

using namespace crossrt::engine;

namespace {

const char* kHeader = R"(#pragma once
#include "LiteMath.h"
#include <vector>
using namespace LiteMath;
struct PointW { float3 p; float w; };   // std430: p@0, w@12, 16 bytes: as C++
struct WPoint { float w; float3 p; };   // std430 puts p at 16, C++ at 4: scalar only
struct TwoPoints { float3 p, q; };      // std430 puts q at 16, C++ at 12: scalar only
struct Padded { float4 a; float b; };   // 32 bytes in both
struct Pair { float2 a; float b; };     // 16 bytes in both (aligned to 8)
class Layouts
{
public:
  virtual ~Layouts() = default;
  virtual void Run(int n);
protected:
  void kernel1D_Touch(int n);
  std::vector<float3> m_float3s;
  std::vector<float4> m_float4s;
  std::vector<PointW> m_pointWs;
  std::vector<WPoint> m_wPoints;
  std::vector<TwoPoints> m_twoPoints;
  std::vector<Padded> m_padded;
  std::vector<Pair> m_pairs;
  float m_scale = 1.0f;
  float2 m_offset;
  float3 m_tint;
  float4x4 m_matrix;
};
)";

const char* kSource = R"(#include "Layouts.h"
void Layouts::Run(int n) { kernel1D_Touch(n); }
void Layouts::kernel1D_Touch(int n)
{
  for (int i = 0; i < n; ++i)
  {
    const float s = m_scale * m_offset.x * m_tint.y * m_matrix[0][0];
    m_float3s[i] = m_float3s[i] * s;
    m_float4s[i] = m_float4s[i] * s;
    m_pointWs[i].w = s;
    m_wPoints[i].w = s;
    m_twoPoints[i].q = m_twoPoints[i].p;
    m_padded[i].b = s;
    m_pairs[i].b = s;
  }
}
)";
}  // namespace

TEST_CASE("Layouts: vector elements get std430 where it reproduces C++, scalar where only it does", "[engine][layout]")
{
  TempClass tc("Layouts", kHeader, kSource);
  const AnalyzeResult r = Analyze(MakeRequest(tc, "Layouts"));
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  const std::pair<const char*, bool> expected[] = {{"m_float3s", true},  {"m_float4s", false}, {"m_pointWs", false}, {"m_wPoints", true},
                                                   {"m_twoPoints", true}, {"m_padded", false}, {"m_pairs", false}};
  for (auto& [name, scalar] : expected)
  {
    INFO(name);
    CHECK(MemberNamed(r.model, name).kind == MemberKind::Vector);
    CHECK(MemberNamed(r.model, name).scalarLayout == scalar);
  }
  // The generated shader declares each buffer in the layout the model chose.
  TempClass again("Layouts", kHeader, kSource);
  const TranslateResult t = Translate(MakeRequest(again, "Layouts"));
  REQUIRE(t.ok);
  const std::string glsl = Squeezed(t.files.at("shaders/kernel1D_Touch.comp"));
  CHECK(glsl.find(Squeezed("layout(scalar, binding")) != std::string::npos);
  CHECK(glsl.find(Squeezed("#extension GL_EXT_scalar_block_layout : require")) != std::string::npos);
}

TEST_CASE("Layouts: plain members join the class data at their std430 alignment", "[engine][layout]")
{
  TempClass tc("Layouts", kHeader, kSource);
  const AnalyzeResult r = Analyze(MakeRequest(tc, "Layouts"));
  REQUIRE(r.ok);
  const std::pair<const char*, unsigned> expected[] = {{"m_scale", 4}, {"m_offset", 8}, {"m_tint", 16}, {"m_matrix", 16}};
  for (auto& [name, align] : expected)
  {
    INFO(name);
    CHECK(MemberNamed(r.model, name).inClassData);
    CHECK(MemberNamed(r.model, name).std430Align == align);
  }
}

TEST_CASE("Layouts: elements no GPU layout reproduces are a diagnostic", "[engine][layout]")
{
  // bool is 1 byte in C++ and 4 in GLSL: neither layout gives the C++ offsets.
  std::string header = kHeader;
  header.replace(header.find("struct Pair { float2 a; float b; };"), std::string("struct Pair { float2 a; float b; };").size(),
                 "struct Pair { bool a; float b; };");
  std::string source = kSource;
  source.replace(source.find("m_pairs[i].b = s;"), std::string("m_pairs[i].b = s;").size(), "m_pairs[i].b = m_pairs[i].a ? s : 0.0f;");
  TempClass tc("Layouts", header, source);
  const AnalyzeResult r = Analyze(MakeRequest(tc, "Layouts"));
  CHECK_FALSE(r.ok);
  CHECK(r.diagnostics.find("error:") != std::string::npos);
  CHECK(r.diagnostics.find("layout") != std::string::npos);
  CHECK(r.diagnostics.find("hint:") != std::string::npos);
}

TEST_CASE("Layouts: ISPC structs pad to C++'s offsets in 32-bit words where they can", "[engine][layout][ispc]")
{
  // A struct returned from a helper inside an `if` is stored masked on ISPC, member by member: a
  // padding byte array is a store per lane and byte with avx2 (no masked byte stores there), a
  // padding word array a masked vector store per word. The fields stay where C++ has them.
  const char* header = R"(#pragma once
#include "LiteMath.h"
#include <vector>
using namespace LiteMath;
struct Sample { float4 dir; uint32_t flags; };  // 12 bytes of padding after flags
struct Marked { float4 dir; bool hit; };        // 15 after hit: 3 to its word, then 12
class Padding
{
public:
  virtual ~Padding() = default;
  virtual void Run(int n);
protected:
  void kernel1D_Pick(int n);
  std::vector<Sample> m_samples;
  std::vector<float4> m_out;
};
)";
  const char* source = R"(#include "Padding.h"
static Sample Pick(float4 d, uint32_t f) { Sample s; s.dir = d; s.flags = f; return s; }
static Marked Mark(float4 d) { Marked m; m.dir = d; m.hit = d.x > 0.0f; return m; }
void Padding::Run(int n) { kernel1D_Pick(n); }
void Padding::kernel1D_Pick(int n)
{
  for (int i = 0; i < n; ++i)
  {
    Sample s = m_samples[i];
    if (s.flags != 0u)
      s = Pick(s.dir * 2.0f, s.flags + 1u);
    const Marked m = Mark(s.dir);
    m_out[i] = m.hit ? s.dir : float4(float(s.flags));
  }
}
)";
  TempClass tc("Padding", header, source);
  const TranslateResult t = Translate(MakeRequest(tc, "Padding", Backend::Ispc));
  INFO(t.diagnostics);
  REQUIRE(t.ok);
  const std::string ispc = Squeezed(t.files.at("Padding_ISPC_kernels.ispc"));
  CHECK(ispc.find(Squeezed("float4 dir; uint flags; uint32 crt_pad0[3]; };")) != std::string::npos);
  CHECK(ispc.find(Squeezed("float4 dir; bool hit; uint8 crt_pad0[3]; uint32 crt_pad1[3]; };")) != std::string::npos);
  CHECK(ispc.find("uint8 crt_pad0[12]") == std::string::npos);
}
