// The GLSL printer (print/KernelPrinter.cpp, print/glsl/GlslPrinter.cpp): what a kernel's C++ becomes, on a small class with a
// user struct, a member helper, a static helper of the .cpp, a local array, a switch, casts and
// the standard library. The expectations are GLSL's spellings of the same C++.
#include "EngineSupport.h"

using namespace crossrt::engine;

namespace {

const char* kHeader = R"(#pragma once
#include "LiteMath.h"
#include <vector>
#include <cstdint>
#include <limits>
using namespace LiteMath;
struct Ray { float3 origin; float tmax; float3 dir; uint32_t id; };
class Printer
{
public:
  virtual ~Printer() = default;
  virtual void Run(int n, [[crossrt::size("n")]] const Ray* rays, [[crossrt::size("n")]] float* out);
protected:
  void kernel1D_Shade(int n, const Ray* rays, float* out);
  float Falloff(float d) const;
  float m_exposure = 1.0f;
};
)";

const char* kSource = R"(#include "Printer.h"
#include <algorithm>
#include <cmath>
static float Square(float x) { return x * x; }
void Printer::Run(int n, const Ray* rays, float* out) { kernel1D_Shade(n, rays, out); }
float Printer::Falloff(float d) const { return 1.0f / (1.0f + Square(d)); }
void Printer::kernel1D_Shade(int n, const Ray* rays, float* out)
{
  for (int i = 0; i < n; ++i)
  {
    const Ray ray = rays[i];
    float weights[3] = {0.25f, 0.5f, 0.25f};
    float sum = 0.0f;
    for (int k = 0; k < 3; ++k) sum += weights[k] * Falloff(float(k) * length(ray.dir));
    const int bucket = static_cast<int>(ray.id % 4u);
    float v = bucket == 0 ? sum : std::max(sum, 0.5f);
    switch (bucket)
    {
    case 1: v *= 2.0f; break;
    case 2: v = std::sqrt(v); break;
    default: break;
    }
    out[i] = v * m_exposure + dot(ray.origin, normalize(ray.dir));
  }
}
)";

size_t Count(const std::string& text, const std::string& piece)
{
  size_t n = 0;
  for (size_t at = text.find(piece); at != std::string::npos; at = text.find(piece, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("Printer: a kernel's C++ in GLSL's spelling, helpers once and ahead of their callers", "[engine][printer]")
{
  TempClass tc("Printer", kHeader, kSource);
  const TranslateResult r = Translate(MakeRequest(tc, "Printer"));
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  const std::string glsl = Squeezed(r.files.at("shaders/kernel1D_Shade.comp"));
  INFO(r.files.at("shaders/kernel1D_Shade.comp"));
  // The user's struct, field for field in GLSL types.
  CHECK(glsl.find(Squeezed("struct Ray")) != std::string::npos);
  CHECK(glsl.find(Squeezed("vec3 origin; float tmax; vec3 dir; uint id; };")) != std::string::npos);
  // Helpers: the .cpp's static function and the const member function become free functions,
  // each printed once, callees before callers.
  const size_t square = glsl.find(Squeezed("float Square(float x)")), falloff = glsl.find(Squeezed("float Falloff(float d)")),
               kernel = glsl.find(Squeezed("void kernel1D_Shade(int i)"));
  REQUIRE(square != std::string::npos);
  REQUIRE(falloff != std::string::npos);
  REQUIRE(kernel != std::string::npos);
  CHECK((square < falloff && falloff < kernel));
  CHECK(Count(glsl, Squeezed("float Square(float x)")) == 1);
  // Statements and expressions.
  CHECK(glsl.find(Squeezed("float weights[3] = float[3](0.25, 0.5, 0.25);")) != std::string::npos);  // array constructor
  CHECK(glsl.find(Squeezed("sum += weights[k] * Falloff(float(k) * length(ray.dir));")) != std::string::npos);
  CHECK(glsl.find(Squeezed("const int bucket = int(ray.id % 4u);")) != std::string::npos);  // static_cast
  CHECK(glsl.find(Squeezed("float v = bucket == 0 ? sum : max(sum, 0.5);")) != std::string::npos);  // std::max
  CHECK(glsl.find(Squeezed("switch (bucket) { case 1: v *= 2.0; break; case 2: v = sqrt(v); break; default: break; }")) !=
        std::string::npos);
  // 'out' is a GLSL keyword: the parameter's buffer is out_.
  CHECK(glsl.find(Squeezed("out_[i] = v * m_exposure + dot(ray.origin, normalize(ray.dir));")) != std::string::npos);
}

TEST_CASE("Printer: recursion in a kernel's reach is a diagnostic at the call", "[engine][printer]")
{
  std::string source = kSource;
  source.replace(source.find("return 1.0f / (1.0f + Square(d));"), std::string("return 1.0f / (1.0f + Square(d));").size(),
                 "return d > 1.0f ? Falloff(d - 1.0f) : 1.0f;");
  TempClass tc("Printer", kHeader, source);
  const TranslateResult r = Translate(MakeRequest(tc, "Printer"));
  CHECK_FALSE(r.ok);
  INFO(r.diagnostics);
  CHECK(r.diagnostics.find("Printer.cpp:6:59: error: recursive call to 'Printer::Falloff' in a kernel") != std::string::npos);
  CHECK(r.diagnostics.find("hint:") != std::string::npos);
}

TEST_CASE("Printer: a branch that GangSize() decides prints only the branch a gang of one takes, and a local that shadows a parameter takes a suffix",
          "[engine][printer]")
{
  std::string source = kSource;
  source.replace(source.find("#include <cmath>"), 16, "#include <cmath>\n#include \"Gang.h\"");
  const std::string last = "    out[i] = v * m_exposure";
  source.replace(source.find(last), last.size(),
                 "    if (crossrt::GangSize() > 1 && v > 0.0f) v = -7.0f;\n"               // never with a gang of one
                 "    if (!(crossrt::GangSize() == 4) || Falloff(v) < 0.0f) v += 0.125f;\n"  // always, Falloff not called
                 "    if (crossrt::GangSize() != 1) v = -9.0f; else v *= 3.0f;\n"           // the else-branch alone
                 "    if (crossrt::GangSize() == 1 && v > 2.0f) v -= 0.0625f;\n"            // the gang's term left out
                 "    { const int n = 2; v += float(n); }\n"                                 // shadows the parameter n
                 + last);
  TempClass tc("Printer", kHeader, source);
  const TranslateResult r = Translate(MakeRequest(tc, "Printer"));
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  const std::string text = r.files.at("shaders/kernel1D_Shade.comp"), glsl = Squeezed(text);
  INFO(text);
  CHECK(glsl.find("-7.0") == std::string::npos);
  CHECK(glsl.find("-9.0") == std::string::npos);
  CHECK(glsl.find(Squeezed("// if (crossrt::GangSize() > 1 && v > 0.0f): false with a gang of 1")) != std::string::npos);
  CHECK(glsl.find(Squeezed("): true with a gang of 1\nv += 0.125;")) != std::string::npos);
  CHECK(glsl.find(Squeezed("): false with a gang of 1\nv *= 3.0;")) != std::string::npos);
  CHECK(glsl.find(Squeezed("if (v > 2.0) v -= 0.0625;")) != std::string::npos);
  CHECK(Count(glsl, "Falloff(v)<0.0)") == 0);  // (the comment has the C++, 0.0f)
  CHECK(glsl.find(Squeezed("{ const int n_1 = 2; v += float(n_1); }")) != std::string::npos);
}

TEST_CASE("Printer: a helper marked noinline stays a call on ISPC, in both spellings, and GLSL has no such qualifier", "[engine][printer][ispc]")
{
  const char* header = R"(#pragma once
#include <vector>
class Cold
{
public:
  virtual ~Cold() = default;
  virtual void Run(int n, float* out);
protected:
  void kernel1D_Run(int n, float* out);
};
)";
  const char* source = R"(#include "Cold.h"
[[gnu::noinline]] static float Rare(float x) { return x * x - 1.0f; }
__attribute__((noinline)) static float Rarer(float x) { return 2.0f * x; }
static float Hot(float x) { return x + 1.0f; }
void Cold::Run(int n, float* out) { kernel1D_Run(n, out); }
void Cold::kernel1D_Run(int n, float* out)
{
  for (int i = 0; i < n; ++i)
    out[i] = i % 7 == 0 ? Rare(float(i)) + Rarer(float(i)) : Hot(float(i));
}
)";
  TempClass tc("Cold", header, source);
  const TranslateResult ispc = Translate(MakeRequest(tc, "Cold", Backend::Ispc));
  INFO(ispc.diagnostics);
  REQUIRE(ispc.ok);
  const std::string kernels = Squeezed(ispc.files.at("Cold_ISPC_kernels.ispc"));
  CHECK(kernels.find(Squeezed("static noinline float Rare(float x)")) != std::string::npos);
  CHECK(kernels.find(Squeezed("static noinline float Rarer(float x)")) != std::string::npos);
  CHECK(kernels.find(Squeezed("static inline float Hot(float x)")) != std::string::npos);
  TempClass again("Cold", header, source);
  const TranslateResult glsl = Translate(MakeRequest(again, "Cold"));
  REQUIRE(glsl.ok);
  const std::string shader = Squeezed(glsl.files.at("shaders/kernel1D_Run.comp"));
  CHECK(shader.find(Squeezed("float Rare(float x)")) != std::string::npos);
  CHECK(shader.find("noinline") == std::string::npos);
}

TEST_CASE("Printer: ISPC divides 32-bit integers that differ per lane through crt_div and crt_rem, and keeps / and % for constants, uniform operands and 64 bits",
          "[engine][printer][ispc]")
{
  const char* header = R"(#pragma once
#include <cstdint>
class Quotients
{
public:
  virtual ~Quotients() = default;
  virtual void Run(int n, const int* a, int* out, unsigned* outU);
protected:
  void kernel1D_Run(int n, const int* a, int* out, unsigned* outU);
  int m_step = 3;
  unsigned m_count = 5u;
};
)";
  const char* source = R"(#include "Quotients.h"
void Quotients::Run(int n, const int* a, int* out, unsigned* outU) { kernel1D_Run(n, a, out, outU); }
void Quotients::kernel1D_Run(int n, const int* a, int* out, unsigned* outU)
{
  for (int i = 0; i < n; ++i)
  {
    const int x = a[i];
    const int perLane = x / (i + 1) + x % (i + 1);
    const int shared = x / m_step;
    const int constant = x / 7 + x % 8;
    const int uniformOnly = m_step / 2 + n / m_step;
    const unsigned u = unsigned(x) / m_count + unsigned(x) % m_count;
    const long long wide = (long long)x / (long long)(i + 1);
    out[i] = perLane + shared + constant + uniformOnly + int(wide);
    outU[i] = u;
  }
}
)";
  TempClass tc("Quotients", header, source);
  const TranslateResult ispc = Translate(MakeRequest(tc, "Quotients", Backend::Ispc));
  INFO(ispc.diagnostics);
  REQUIRE(ispc.ok);
  const std::string kernels = Squeezed(ispc.files.at("Quotients_ISPC_kernels.ispc"));
  INFO(kernels);
  // Per lane, or a lane's value by a member all lanes share: in the vector.
  CHECK(kernels.find(Squeezed("crt_div((varying int)(x), (varying int)((i + 1)))")) != std::string::npos);
  CHECK(kernels.find(Squeezed("crt_rem((varying int)(x), (varying int)((i + 1)))")) != std::string::npos);
  CHECK(kernels.find(Squeezed("crt_div((varying int)(x), (varying int)(self->m_step))")) != std::string::npos);
  CHECK(Count(kernels, Squeezed("crt_div((varying uint)")) == 1);
  CHECK(Count(kernels, Squeezed("crt_rem((varying uint)")) == 1);
  // A constant divisor (a multiplication to ISPC), uniform operands and 64-bit integers keep the operator.
  CHECK(kernels.find(Squeezed("x / 7")) != std::string::npos);
  CHECK(kernels.find(Squeezed("(varying int)(self->m_step), (varying int)(2)")) == std::string::npos);
  CHECK(kernels.find(Squeezed("crt_div((varying int)(n)")) == std::string::npos);
  CHECK(Count(kernels, "crt_div(") == 3);
  CHECK(Count(kernels, "crt_rem(") == 2);
  // GLSL divides in the vector: the operators as written.
  TempClass again("Quotients", header, source);
  const TranslateResult glsl = Translate(MakeRequest(again, "Quotients"));
  REQUIRE(glsl.ok);
  CHECK(glsl.files.at("shaders/kernel1D_Run.comp").find("crt_div") == std::string::npos);
}
