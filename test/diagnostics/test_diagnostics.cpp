// Each construct the translator cannot handle gets a compiler-style diagnostic that points at the
// user's code (file:line:col: error:), names the construct and gives a hint. The real crossrt
// command runs on each case: it must exit with status 1, never crash, and write no output files.
#include "EngineSupport.h"

#include <fstream>
#include <iterator>
#include <regex>

namespace {

struct Case
{
  const char* name;
  const char* kernelBody;      // body of kernel1D_Bad's loop (line 8 of Bad.cpp is its first line)
  const char* extraHeader;     // extra members or helpers in the class
  const char* extraSource;     // extra definitions in Bad.cpp
  const char* expectedMessage;
  const char* expectedHint;
  int expectedLine;            // in Bad.cpp
};

std::string Header(const Case& c)
{
  return std::string(R"(#pragma once
#include "LiteMath.h"
#include "Atomics.h"
#include "Gang.h"
#include <vector>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
class Bad
{
public:
  virtual ~Bad() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* data);
protected:
  void kernel1D_Bad(int n, float* data);
  float m_value = 1.0f;
)") + c.extraHeader + "\n};\n";
}

std::string Source(const Case& c)
{
  return std::string(R"(#include "Bad.h"
void Bad::Run(int n, float* data) { kernel1D_Bad(n, data); }
void Bad::kernel1D_Bad(int n, float* data)
{
  for (int i = 0; i < n; i++)
  {
    float x = data[i];
)") + c.kernelBody + "\n    data[i] = x;\n  }\n}\n" + c.extraSource;
}

const Case kCases[] = {
    {"recursion", "    x = Fact(x);", "  float Fact(float v) const;",
     "float Bad::Fact(float v) const { return v <= 1.0f ? 1.0f : v * Fact(v - 1.0f); }\n",
     "recursive call to 'Bad::Fact' in a kernel", "explicit stack", 12},
    {"new", "    float* p = new float[4]; x += p[0];", "", "", "'new' in a kernel (heap allocation)", "cannot allocate", 8},
    {"an object's field through a local pointer to it",
     "    const Shape* s = m_shapes[i % 2];\n    x += s->Area() + s->size;",
     "  struct Shape { virtual ~Shape() = default; virtual float Area() const { return size * size; } float size = 1.0f; };\n"
     "  std::vector<Shape*> m_shapes;",
     "", "'s' points at an element of m_shapes, which kernels hold as its index: it can only call virtual methods here",
     "call them as s->Method(...)", 9},
    {"a null test of a local pointer to an object",
     "    const Shape* s = m_shapes[i % 2];\n    if (s != nullptr) x += s->Area();",
     "  struct Shape { virtual ~Shape() = default; virtual float Area() const { return 1.0f; } };\n"
     "  std::vector<Shape*> m_shapes;",
     "", "nullptr in a kernel", "test an index or a count instead", 9},
    {"delete", "    delete[] data;", "", "", "'delete' in a kernel (heap allocation)", "cannot allocate", 8},
    {"malloc", "    x += float(std::malloc(4) != nullptr);", "", "", "heap allocation ('malloc') in a kernel", "cannot allocate", 8},
    {"printf", "    std::printf(\"%f\\n\", x);", "", "", "I/O ('printf') in a kernel", "write results to an output buffer", 8},
    {"iostream", "    std::cout << x;", "", "", "I/O (stream operator) in a kernel", "write results to an output buffer", 8},
    {"library call", "    x += float(std::strlen(\"abc\"));", "", "", "unsupported library call 'strlen' in a kernel", "kernels may call LiteMath", 8},
    {"member race", "    m_value = x;", "", "", "kernel writes class member 'm_value' from every thread", "reduction", 8},
    {"double", "    double d = x; x = float(d);", "", "", "type 'double' is not supported in Vulkan kernels", "use float", 8},
    {"narrow integer", "    short s = short(x); x = float(s);", "", "", "narrower than 32 bits", "use int", 8},
    {"helper writes member", "    x = Touch(x);", "  float Touch(float v);", "float Bad::Touch(float v) { m_value = v; return v; }\n",
     "helper function 'Touch' writes class member 'm_value'", "return the value", 12},
    {"return in loop", "    if (x > 0.0f) return;", "", "", "'return' inside a parallel kernel loop would end all later iterations", "'continue'", 8},
    {"atomic on a local", "    uint32_t hits = 0; crossrt::AtomicAdd(hits, 1u); x += float(hits);", "", "",
     "the target of crossrt::AtomicAdd is not in device memory: 'hits' is a local variable", "element of a std::vector member", 8},
    {"atomic through a helper's reference", "    Count(m_counts[i]);", "  std::vector<uint32_t> m_counts;\n  void Count(uint32_t& c);",
     "void Bad::Count(uint32_t& c) { crossrt::AtomicAdd(c, 1u); }\n",
     "reference parameter 'c' is a copy on the GPU", "element of a std::vector member", 12},
    {"a vector passed to a helper", "    x += Sum(m_weights);", "  std::vector<float> m_weights;\n  float Sum(const std::vector<float>& w) const;",
     "float Bad::Sum(const std::vector<float>& w) const { float s = 0.0f; for (size_t k = 0; k < w.size(); ++k) s += w[k]; return s; }\n",
     "call to 'std::vector<float>::size' on a std::vector that is not a data member, in a kernel", "make the helper a member function that reads the member", 12},
    {"a range-based for over a braced list", "    for (float v : {1.0f, 2.0f}) x += v;", "", "",
     "a range-based for over 'std::initializer_list<float>' in a kernel", "index other ranges", 8},
    {"a generic lambda", "    auto twice = [](auto v) { return v + v; }; x = twice(x);", "", "", "a generic lambda (auto parameters) in a kernel",
     "give its parameters types", 8},
    {"a lambda capturing a pointer", "    float* p = &x; auto bump = [p]() { *p += 1.0f; }; bump();", "", "",
     "a lambda in a kernel capturing 'p', a pointer or reference", "capture the value", 8},
    {"a lambda passed on", "    auto keep = [](float v) { return v > 0.0f; }; x = Apply(keep, x);", "  template <class F> float Apply(F f, float v) { return f(v) ? v : 0.0f; }", "",
     "a lambda used other than by calling it", "keep it in a local and call it", 8},
    {"a reference whose element changes", "    int k = i; float& r = data[k]; k = 0; r += 1.0f; x = r;", "", "",
     "non-const reference variable in a kernel: 'k', which picks what it refers to, changes after it", "write through the original expression", 8},
    {"a local under the generated code's prefix", "    float crt_sum = x; x = crt_sum * 2.0f;", "", "",
     "variable 'crt_sum' begins with crt_, which CrossRT keeps for the names of the code it generates", "rename it", 8},
    {"nested control", "", "  virtual void Outer(int n, [[crossrt::size(\"n\")]] float* data);", "void Bad::Outer(int n, float* data) { kernel1D_Bad(n, data); Run(n, data); }\n",
     "control function 'Outer' calls control function 'Run'", "one submission", 12},
};

// Translates the case's class for `backend`: exit status 1, no crash, nothing written, and an
// error at the expected line of Bad.cpp with the expected message and hint.
void RequireDiagnostic(const Case& c, const std::string& backend)
{
  TempClass tc("Bad", Header(c), Source(c));
  const std::string out = (tc.dir / "out").string();
  CommandResult r = RunCrossrt("translate --class Bad --backend " + backend + " --out " + out + " --source " + tc.Source("Bad") +
                               " --templates " CROSSRT_SOURCE_DIR "/templates -- -I" CROSSRT_SOURCE_DIR "/libs/litemath");
  INFO(r.output);
  REQUIRE_FALSE(r.crashed);
  REQUIRE(r.exitCode == 1);
  const std::string where = tc.Source("Bad") + ":" + std::to_string(c.expectedLine) + ":";
  REQUIRE(r.output.find(where) != std::string::npos);
  REQUIRE(std::regex_search(r.output, std::regex(R"(Bad\.cpp:\d+:\d+: error: )")));
  REQUIRE(r.output.find(c.expectedMessage) != std::string::npos);
  REQUIRE(r.output.find("note: hint: ") != std::string::npos);
  REQUIRE(r.output.find(c.expectedHint) != std::string::npos);
  REQUIRE_FALSE(fs::exists(out));  // nothing written on failure
}

}  // namespace

TEST_CASE("Unsupported constructs in kernels give file:line:col diagnostics with hints", "[diagnostics]")
{
  for (const Case& c : kCases)
  {
    SECTION(c.name) { RequireDiagnostic(c, "vulkan"); }
  }
}

TEST_CASE("What the ISPC backend does not translate yet is an error at the user's code, with a hint", "[diagnostics][ispc]")
{
  const Case ispcCases[] = {
      {"hmax of an expression with side effects", "    int k = 0; x = LiteMath::hmax(LiteMath::float4(float(k++)));", "", "",
       "hmin/hmax of an expression with side effects is not translated to ISPC yet", "BACKEND cpu (all cores, no SIMD lanes) or vulkan", 8},
      {"a component updated through an index with side effects", "    LiteMath::float4 v(x); int k = i; v[k++ % 4] += 1.0f; x = v.x;", "", "",
       "compound assignment to a vector's component whose vector or index has side effects is not translated to ISPC yet",
       "BACKEND cpu (all cores, no SIMD lanes) or vulkan", 8},
      // (A local matrix's column, m[k++] += v, translates: the transforms conformance case.)
      {"a column of an array's matrix updated through an index with side effects",
       "    LiteMath::float4x4 ms[2]; int k = 0; ms[1][k++] += LiteMath::float4(x); x = ms[1](0, 0);", "",
       "", "compound assignment to a vector whose address has side effects, other than an element of a buffer, member vector or local array, is not translated to ISPC yet", "BACKEND cpu (all cores, no SIMD lanes) or vulkan", 8},
      // The gang (Gang.h): what a CRT_UNIFORM local holds must be the same in every lane.
      {"a per-lane value kept in a CRT_UNIFORM local", "    CRT_UNIFORM int k = 0;\n    k = i;\n    x += float(k);", "", "",
       "a value that may differ between the lanes of an ISPC gang is assigned to CRT_UNIFORM 'k'", "crossrt::AnyLane, FirstLane, LaneValue, LaneBits or MinOverLanes", 9},
      {"a per-lane value starting a CRT_UNIFORM local", "    CRT_UNIFORM const float y = x;\n    x += y;", "", "",
       "a value that may differ between the lanes of an ISPC gang is assigned to CRT_UNIFORM 'y'", "declare 'y' without CRT_UNIFORM", 8},
      {"a CRT_UNIFORM array written at a per-lane index", "    CRT_UNIFORM float a[4] = {0.0f, 0.0f, 0.0f, 0.0f};\n    a[i % 4] = 1.0f;\n    x += a[0];", "", "",
       "an index that may differ between the lanes of an ISPC gang into CRT_UNIFORM 'a'", "crossrt::AnyLane", 9},
      {"a CRT_UNIFORM struct", "    CRT_UNIFORM LiteMath::float4 v(1.0f);\n    x += v.x;", "", "",
       "CRT_UNIFORM local 'v' of type 'LiteMath::float4'", "declare the struct's fields as CRT_UNIFORM locals", 8},
      {"a CRT_UNIFORM local passed by reference", "    CRT_UNIFORM int k = 0;\n    Bump(k);\n    x += float(k);",
       "  void Bump(int& k) const;", "void Bad::Bump(int& k) const { k = k + 1; }\n",
       "CRT_UNIFORM 'k' is passed to reference parameter 'k', which holds one value per lane on ISPC", "return the new value", 9},
      {"the first lane of a vector", "    x += crossrt::FirstLane(LiteMath::float2(x, x)).x;", "", "",
       "crossrt::FirstLane of a 'LiteMath::float2'", "one field at a time", 8},
      {"the lane of LaneValue differing between lanes", "    x += crossrt::LaneValue(x, i % 4);", "", "",
       "the lane of crossrt::LaneValue may differ between the lanes of an ISPC gang", "FirstLane of a parameter", 8},
      {"LaneOf of a 3-vector", "    x += crossrt::LaneOf(LiteMath::float3(x), 0);", "", "", "crossrt::LaneOf of a 'LiteMath::float3'",
       "pass a LiteMath float4, int4 or uint4", 8},
      {"LaneOfQuad of a 3-vector", "    x += crossrt::LaneOfQuad(LiteMath::float3(x));", "", "", "crossrt::LaneOfQuad of a 'LiteMath::float3'",
       "pass a LiteMath float4, int4 or uint4", 8},
      {"FromLane of a vector", "    x += crossrt::FromLane(LiteMath::float2(x, x), i % 4).x;", "", "",
       "crossrt::FromLane of a 'LiteMath::float2'", "one field at a time", 8},
      {"LaneOf from a component differing between lanes", "    x += crossrt::LaneOf(LiteMath::float4(x), i % 4);", "", "",
       "the first component of crossrt::LaneOf may differ between the lanes of an ISPC gang", "a shared loop's variable", 8},
      {"a per-lane local written in a loop whose lanes share out its items",
       "    float s = 0.0f;\n    for (int f = 0; f < 4; f += crossrt::GangSize())\n      s += float(f + crossrt::LaneIndex());\n    x += s;", "", "",
       "a write to 's' inside a loop that shares its items out over the gang's lanes", "write the loop's own locals and CRT_UNIFORM locals", 10},
      // An AllLanesOn branch is `unmasked` on ISPC, which a return inside mishandles.
      {"a return inside a crossrt::AllLanesOn() branch", "    x = Twice(x);", "  float Twice(float v) const;",
       "float Bad::Twice(float v) const { if (crossrt::AllLanesOn()) return v * 2.0f; return v + v; }\n",
       "'return' inside a crossrt::AllLanesOn() branch", "assign the result to a local declared before the if", 12},
  };
  for (const Case& c : ispcCases)
  {
    SECTION(c.name) { RequireDiagnostic(c, "ispc"); }
  }
}

namespace {

// Translates class `name` of `tc` for ISPC (LiteMath on the include path) and returns its kernels file.
std::string IspcKernelsOf(const TempClass& tc, const std::string& name)
{
  CommandResult r = RunCrossrt("translate --class " + name + " --backend ispc --out " + (tc.dir / "out").string() + " --source " +
                               tc.Source(name) + " --templates " CROSSRT_SOURCE_DIR "/templates -- -I" CROSSRT_SOURCE_DIR "/libs/litemath");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  std::ifstream file(tc.dir / "out" / (name + "_ISPC_kernels.ispc"));
  return std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
}

}  // namespace

TEST_CASE("ISPC: a loop whose bounds every lane shares is uniform, and leaves early only all at once, one the lanes differ in, or leave early apart, is varying", "[diagnostics][ispc]")
{
  TempClass tc("Loops", R"(#pragma once
class Loops
{
public:
  virtual ~Loops() = default;
  virtual void Run(int n, int taps, [[crossrt::size("n")]] float* data);
  int m_radius = 2;
protected:
  void kernel1D_Run(int n, int taps, float* data);
};
)",
               R"(#include "Loops.h"
void Loops::Run(int n, int taps, float* data) { kernel1D_Run(n, taps, data); }
void Loops::kernel1D_Run(int n, int taps, float* data)
{
  for (int i = 0; i < n; i++)
  {
    float x = data[i];
    for (int k = -m_radius; k <= m_radius; k++)
      for (int t = 0; t < taps * k; t += 2)
        x += 0.5f;
    for (int j = 0; j < i % 4; j++)
      x *= 2.0f;
    for (int e = 0; e < taps; e++)
      if (x > 100.0f)
        break;
    for (int s = 0; s < taps; s++)  // leaves early, but every lane at once (its conditions are shared)
    {
      if (s * m_radius > 8)
        break;
      if (s == 1)
        continue;
      for (int w = 0; w < i % 3; w++)  // a varying inner loop's break leaves only that loop
        if (x > 50.0f)
          break;
      x += float(s);
    }
    for (int c = 0; c < taps; c++)  // leaves in the lanes whose case it is
    {
      switch (i % 2)
      {
        case 0: continue;
        default: break;
      }
      x += 1.0f;
    }
    data[i] = x;
  }
}
)");
  const std::string text = IspcKernelsOf(tc, "Loops");
  INFO(text);
  REQUIRE(text.find("for (uniform int s = 0; s < taps; s++)") != std::string::npos);  // shared early exits
  REQUIRE(text.find("for (int c = 0;") != std::string::npos);  // a continue under a per-lane switch
  REQUIRE(text.find("for (uniform int k = -self->m_radius; k <= self->m_radius; k++)") != std::string::npos);  // members
  REQUIRE(text.find("for (uniform int t = 0; t < taps * k; t += 2)") != std::string::npos);  // a parameter, an outer uniform loop
  REQUIRE(text.find("for (int j = 0;") != std::string::npos);  // a bound per lane
  REQUIRE(text.find("for (int e = 0;") != std::string::npos);  // some lanes may leave early
}

TEST_CASE("ISPC: CRT_UNIFORM locals are uniform, and crossrt::AnyLane, AllLanes, FirstLane, MinOverLanes and GangSize are the gang's",
          "[diagnostics][ispc]")
{
  TempClass tc("Packets", R"(#pragma once
#include "Gang.h"
#include <vector>
class Packets
{
public:
  virtual ~Packets() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* data);
  std::vector<unsigned> m_next;
protected:
  void kernel1D_Run(int n, float* data);
};
)",
               R"(#include "Packets.h"
void Packets::Run(int n, float* data) { kernel1D_Run(n, data); }
void Packets::kernel1D_Run(int n, float* data)
{
  for (int i = 0; i < n; i++)
  {
    CRT_UNIFORM unsigned node = crossrt::FirstLane(unsigned(i) % 4u);
    CRT_UNIFORM float stack[4] = {0.0f, 1.0f, 2.0f, 3.0f};
    CRT_UNIFORM int top = 0;
    float x = data[i];
    while (crossrt::AnyLane(x > 0.0f) && top < 4)
    {
      stack[top] = crossrt::MinOverLanes(x);
      node = m_next[node];
      top = top + 1;
      x = x - 1.0f;
    }
    if (crossrt::GangSize() > 1 && crossrt::AllLanes(x <= 0.0f))
      x = stack[0] + float(node);
    data[i] = x;
  }
}
)");
  const std::string text = IspcKernelsOf(tc, "Packets");
  INFO(text);
  REQUIRE(text.find("uniform uint node = crt_first_lane(((uint)(i)) % 4u);") != std::string::npos);
  REQUIRE(text.find("uniform float stack[4] = {0.0, 1.0, 2.0, 3.0};") != std::string::npos);
  REQUIRE(text.find("uniform int top = 0;") != std::string::npos);
  REQUIRE(text.find("while (any(x > 0.0) && top < 4)") != std::string::npos);
  REQUIRE(text.find("stack[top] = reduce_min(x);") != std::string::npos);
  REQUIRE(text.find("node = self->m_next[node];") != std::string::npos);  // a member's element at a shared index: shared
  REQUIRE(text.find("if (programCount > 1 && all(x <= 0.0))") != std::string::npos);
  REQUIRE(text.find("x = stack[0] + ((uniform float)(node));") != std::string::npos);  // a shared value's conversion stays shared
}

TEST_CASE("ISPC: a struct of 32 bytes or more read whole at a per-lane index in a const method loads what the lanes agree on once",
          "[diagnostics][ispc]")
{
  TempClass tc("Lookup", R"(#pragma once
#include "LiteMath.h"
#include <vector>
struct Big { LiteMath::float4 lo, hi; };     // 32 bytes
struct Small { float a, b; };                // 8 bytes: a gather is as cheap
class Lookup
{
public:
  virtual ~Lookup() = default;
  virtual void Run(int n, [[crossrt::size("n")]] const unsigned* keys, [[crossrt::size("n")]] float* out);
  std::vector<Big> m_big;
  std::vector<Small> m_small;
protected:
  float Whole(unsigned k) const;
  float Field(unsigned k) const;
  void kernel1D_Run(int n, const unsigned* keys, float* out);
};
)",
               R"(#include "Lookup.h"
void Lookup::Run(int n, const unsigned* keys, float* out) { kernel1D_Run(n, keys, out); }
float Lookup::Whole(unsigned k) const
{
  const Big b = m_big[k];
  const Big first = m_big[0];
  const Small s = m_small[k];
  return b.lo.x + b.hi.y + first.lo.z + s.a;
}
float Lookup::Field(unsigned k) const { return m_big[k].hi.w; }
void Lookup::kernel1D_Run(int n, const unsigned* keys, float* out)
{
  for (int i = 0; i < n; i++)
  {
    const Big mine = m_big[keys[i]];
    out[i] = Whole(keys[i]) + Field(keys[i]) + mine.lo.w;
  }
}
)");
  const std::string text = IspcKernelsOf(tc, "Lookup");
  INFO(text);
  REQUIRE(text.find("static inline Big crt_load_Big(const uniform Big *uniform a, uint i)") != std::string::npos);
  REQUIRE(text.find("const Big b = crt_load_Big(self->m_big, ((uint)(k)));") != std::string::npos);  // const, whole, per lane
  REQUIRE(text.find("const Big first = self->m_big[0u];") != std::string::npos);                   // one index for all lanes
  REQUIRE(text.find("const Small s = self->m_small[k];") != std::string::npos);                    // small: a gather
  REQUIRE(text.find("return self->m_big[k].hi.w;") != std::string::npos);                          // one field of it: a gather
  REQUIRE(text.find("const Big mine = self->m_big[keys[i]];") != std::string::npos);               // not const: as written
}

TEST_CASE("ISPC: a float4 read whole through a pointer at a per-lane index goes through crt_load4, one stored whole through crt_store4, a field of it does neither",
          "[diagnostics][ispc]")
{
  TempClass tc("Rows", R"(#pragma once
#include "LiteMath.h"
using LiteMath::float4;
class Rows
{
public:
  virtual ~Rows() = default;
  virtual void Run(int n, [[crossrt::size("n")]] const float4* in, [[crossrt::size("n")]] float4* out);
protected:
  void kernel1D_Run(int n, const float4* in, float4* out);
};
)",
               R"(#include "Rows.h"
void Rows::Run(int n, const float4* in, float4* out) { kernel1D_Run(n, in, out); }
void Rows::kernel1D_Run(int n, const float4* in, float4* out)
{
  for (int i = 0; i < n; i++)
  {
    const float4 copied = in[i];
    const float4 first = in[0];
    out[i] = copied + in[i] * 2.0f + float4(in[i].x) + first;
    out[i].w = 1.0f;
  }
}
)");
  const std::string text = IspcKernelsOf(tc, "Rows");
  INFO(text);
  REQUIRE(text.find("const float4 copied = crt_load4(in_, (int)(i));") != std::string::npos);  // copied whole
  REQUIRE(text.find("const float4 first = in_[0];") != std::string::npos);                   // one element for all lanes
  REQUIRE(text.find("crt_load4(in_, (int)(i)) * 2.0") != std::string::npos);                 // passed by const reference
  REQUIRE(text.find("in_[i].x") != std::string::npos);                                        // one field: a gather
  REQUIRE(text.find("crt_store4(out_, (int)(i), copied + ") != std::string::npos);           // stored whole
  REQUIRE(text.find("out_[i].w = 1.0") != std::string::npos);                                 // one field: a scatter
}

TEST_CASE("ISPC: a 4-vector field of a struct of two to four 16-byte rows read at a per-lane index goes through crt_load4_field",
          "[diagnostics][ispc]")
{
  TempClass tc("Fields", R"(#pragma once
#include "LiteMath.h"
#include <vector>
using namespace LiteMath;
struct Three { float4 a; float4 b; int4 c; };               // 48 bytes: three rows
struct Four { float4 p; float4 q; float4 r; uint4 ids; };  // 64 bytes: four rows
struct Five { float4 v[5]; };                              // 80 bytes: too many rows
struct Mixed { float3 lo; float w; float4 hi; };           // two rows, one of them a float3 and a float
class Fields
{
public:
  virtual ~Fields() = default;
  virtual void Run(int n, [[crossrt::size("n")]] const Box4f* boxes, [[crossrt::size("n")]] const Three* threes,
                   [[crossrt::size("n")]] const Five* fives, [[crossrt::size("n")]] const Mixed* mixed, [[crossrt::size("n")]] float4* out);
protected:
  void kernel1D_Run(int n, const Box4f* boxes, const Three* threes, const Five* fives, const Mixed* mixed, float4* out);
  std::vector<Four> m_fours;
};
)",
               R"(#include "Fields.h"
void Fields::Run(int n, const Box4f* boxes, const Three* threes, const Five* fives, const Mixed* mixed, float4* out)
{
  kernel1D_Run(n, boxes, threes, fives, mixed, out);
}
void Fields::kernel1D_Run(int n, const Box4f* boxes, const Three* threes, const Five* fives, const Mixed* mixed, float4* out)
{
  float4 first = float4(0.0f);
  for (int j = 0; j < 2; j++)  // before the nest: one thread's loop, not the lanes'
    first += boxes[j].boxMin;
  for (int i = 0; i < n; i++)
  {
    const float4 lo = boxes[i].boxMin;
    const int4 c = threes[i].c;
    const uint4 ids = m_fours[i].ids;
    float4 sum = lo + boxes[i].boxMax + to_float4(c) + to_float4(ids) + m_fours[i].q;
    sum += fives[i].v[1] + mixed[i].hi + float4(boxes[0].boxMax.x) + float4(boxes[i].boxMin.y);
    const float3 m = mixed[i].lo;
    for (int k = 0; k < 2; k++)  // a loop inside the thread: its index is not the lanes', i still is
      sum += boxes[k].boxMax + threes[i].a;
    out[i] = sum + first + float4(m.x, m.y, m.z, 0.0f);
  }
}
)");
  const std::string text = IspcKernelsOf(tc, "Fields");
  INFO(text);
  REQUIRE(text.find("const float4 lo = crt_load4_field((const uniform float4 *uniform)(boxes), (int)(i), 2, 0);") != std::string::npos);
  REQUIRE(text.find("crt_load4_field((const uniform float4 *uniform)(boxes), (int)(i), 2, 1)") != std::string::npos);  // by const reference
  REQUIRE(text.find("const int4 c = crt_load4_field((const uniform int4 *uniform)(threes), (int)(i), 3, 2);") != std::string::npos);
  REQUIRE(text.find("const uint4 ids = crt_load4_field((const uniform uint4 *uniform)(self->m_fours), (int)(i), 4, 3);") != std::string::npos);
  REQUIRE(text.find("crt_load4_field((const uniform float4 *uniform)(self->m_fours), (int)(i), 4, 1)") != std::string::npos);
  REQUIRE(text.find("fives[i].v[1]") != std::string::npos);        // five rows, and an array field: as written
  REQUIRE(text.find("crt_load4_field((const uniform float4 *uniform)(mixed), (int)(i), 2, 1)") != std::string::npos);
  REQUIRE(text.find("const float3 m = mixed[i].lo;") != std::string::npos);  // a float3 field: as written
  REQUIRE(text.find("boxes[0].boxMax.x") != std::string::npos);    // one element for all lanes
  REQUIRE(text.find("boxes[i].boxMin.y") != std::string::npos);    // one component of the field: a gather
  REQUIRE(text.find("boxes[j].boxMin") != std::string::npos);  // a loop before the nest: as written
  REQUIRE(text.find("boxes[k].boxMax + crt_load4_field((const uniform float4 *uniform)(threes), (int)(i), 3, 0)") != std::string::npos);
}

TEST_CASE("ISPC: a struct of eight 32-bit words stored whole at a per-lane index goes through a crt_store_ helper of its own, other structs scatter",
          "[diagnostics][ispc]")
{
  TempClass tc("Hits", R"(#pragma once
#include <cstdint>
struct Hit { float t; uint32_t prim, inst, geom; float coords[4]; };  // 32 bytes, as CRT_Hit
struct Pair { float a; int b; };                                      // 8 bytes
class Hits
{
public:
  virtual ~Hits() = default;
  virtual void Run(int n, [[crossrt::size("n")]] Hit* hits, [[crossrt::size("n")]] Pair* pairs);
protected:
  void kernel1D_Run(int n, Hit* hits, Pair* pairs);
};
)",
               R"(#include "Hits.h"
void Hits::Run(int n, Hit* hits, Pair* pairs) { kernel1D_Run(n, hits, pairs); }
void Hits::kernel1D_Run(int n, Hit* hits, Pair* pairs)
{
  for (int i = 0; i < n; i++)
  {
    Hit h;
    h.t = float(i);
    h.prim = uint32_t(i);
    h.inst = h.geom = 0u;
    h.coords[0] = h.coords[1] = h.coords[2] = h.coords[3] = 0.5f;
    hits[i] = h;
    Pair p;
    p.a = 1.0f;
    p.b = i;
    pairs[i] = p;
  }
}
)");
  const std::string text = IspcKernelsOf(tc, "Hits");
  INFO(text);
  REQUIRE(text.find("static inline void crt_store_Hit(uniform Hit *uniform a, int i, Hit v)") != std::string::npos);
  REQUIRE(text.find("crt_store_words8((uniform float *uniform)(a + extract(i, 0)), v.t, floatbits((unsigned int32)v.prim), "
                    "floatbits((unsigned int32)v.inst), floatbits((unsigned int32)v.geom), v.coords[0], v.coords[1], v.coords[2], v.coords[3]);") !=
          std::string::npos);
  REQUIRE(text.find("crt_store_Hit(hits, (int)(i), h);") != std::string::npos);
  REQUIRE(text.find("pairs[i] = p;") != std::string::npos);  // not eight words: the scatters
}

TEST_CASE("A pointer parameter of a control function without a size is reported", "[diagnostics]")
{
  TempClass tc("NoSize", R"(#pragma once
class NoSize
{
public:
  virtual ~NoSize() = default;
  virtual void Run(int n, const float* in, float* out);
protected:
  void kernel1D_Copy(int n, const float* in, float* out);
};
)",
               R"(#include "NoSize.h"
void NoSize::Run(int n, const float* in, float* out) { kernel1D_Copy(n, in, out); }
void NoSize::kernel1D_Copy(int n, const float* in, float* out) { for (int i = 0; i < n; i++) out[i] = in[n - 1 - i]; }
)");
  // The Vulkan class copies the arguments to the GPU, so it needs their size (the CPU class does not).
  // 'out' is indexed by the kernel's loop variable only, so the loop's bound is its size (a note says
  // so, as kernel_slicer infers it); 'in' is read backwards, which says nothing of its size.
  CommandResult r = RunCrossrt("translate --class NoSize --backend vulkan --out " + (tc.dir / "out").string() + " --source " + tc.Source("NoSize") +
                               " --templates " CROSSRT_SOURCE_DIR "/templates");
  INFO(r.output);
  REQUIRE(r.exitCode == 1);
  // Reported where the annotation belongs: the declaration in the header.
  REQUIRE(r.output.find("NoSize.h:6:40: error: pointer parameter 'in' of control function 'Run' has no size") != std::string::npos);
  REQUIRE(r.output.find("[[crossrt::size(\"n\")]]") != std::string::npos);
  REQUIRE(r.output.find("NoSize.h:6:51: note: pointer parameter 'out' of control function 'Run' has no size: n elements") != std::string::npos);
}

TEST_CASE("CRT_SPECIALIZE members are specialization constants in GLSL: written by a kernel, changed between kernel calls, or of another type, an error on Vulkan only",
          "[diagnostics][specialize]")
{
  // Line 10 of the header: the member's type; line 5 of the source: the kernel's write; line 3: the
  // control function's change between its kernel calls.
  auto header = [](const std::string& type) {
    return R"(#pragma once
#include "Specialize.h"
#include <vector>
class Modes
{
public:
  virtual ~Modes() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* data);
  virtual void Twice(int n, [[crossrt::size("n")]] float* data);
  CRT_SPECIALIZE )" + type + R"( m_mode{};
  CRT_SPECIALIZE bool m_flip = false;
  CRT_SPECIALIZE unsigned m_last = 0u;
protected:
  void kernel1D_Scale(int n, float* data);
  void Bump() { m_mode = m_mode + 1; }
};
enum Shade { kFlat, kSmooth };  // a plain enum: its constants are ints in expressions
)";
  };
  auto source = [](const std::string& kernelWrite, const std::string& between, const std::string& twice = "") {
    return R"(#include "Modes.h"
void Modes::Run(int n, float* data) { kernel1D_Scale(n, data); }
void Modes::Twice(int n, float* data) { )" + (twice.empty() ? "kernel1D_Scale(n, data); " + between + " kernel1D_Scale(n, data);" : twice) + R"( }
void Modes::kernel1D_Scale(int n, float* data) { for (int i = 0; i < n; i++) {
  )" + kernelWrite + R"(
  data[i] = m_flip ? -data[i] * float(m_mode) : data[i] * float(m_mode); } }
)";
  };
  auto translate = [](const TempClass& tc, const std::string& backend) {
    return RunCrossrt("translate --class Modes --backend " + backend + " --out " + (tc.dir / ("out_" + backend)).string() + " --source " +
                      tc.Source("Modes") + " --templates " CROSSRT_SOURCE_DIR "/templates -- -I" CROSSRT_SOURCE_DIR "/libs/litemath");
  };
  SECTION("read as specialization constants, numbered from kClassConstantIdBase in member order")
  {
    TempClass tc("Modes", header("int"), source("data[i] += float(i - kSmooth < 0 ? 1 : 0);", ""));
    CommandResult r = translate(tc, "vulkan");
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
    std::ifstream file(tc.dir / "out_vulkan" / "shaders" / "kernel1D_Scale.comp");
    const std::string glsl((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    INFO(glsl);
    REQUIRE(glsl.find("layout(constant_id = 1800) const int crt_m_mode_specialized = 0;") != std::string::npos);
    REQUIRE(glsl.find("layout(constant_id = 1801) const bool crt_m_flip_specialized = false;") != std::string::npos);
    REQUIRE(glsl.find("crt_m_flip_specialized ? -data[i] * float(crt_m_mode_specialized)") != std::string::npos);
    REQUIRE(glsl.find("i - int(1) < 0") != std::string::npos);  // a plain enum's constant is an int, as in C++
  }
  SECTION("changed after the last kernel call, also after a loop of them: it applies from the next call")
  {
    TempClass tc("Modes", header("int"), source("", "", "for (int k = 0; k < 2; k++) kernel1D_Scale(n, data); m_mode = m_mode + 1;"));
    CommandResult r = translate(tc, "vulkan");
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
  }
  for (const char* twice : {"for (int k = 0; k < 2; k++) { kernel1D_Scale(n, data); m_mode = m_mode + 1; }",
                            "for (m_mode = 0; m_mode < 2; ++m_mode) kernel1D_Scale(n, data);", "Bump(); kernel1D_Scale(n, data);",
                            "int other = 3; std::swap(m_mode, other); kernel1D_Scale(n, data);"})
  {
    DYNAMIC_SECTION("changed where a kernel call follows: " << twice)
    {
      TempClass tc("Modes", header("int"), "#include <utility>\n" + source("", "", twice));
      CommandResult r = translate(tc, "vulkan");
      INFO(r.output);
      REQUIRE(r.exitCode == 1);
      REQUIRE(r.output.find("control function 'Twice' changes member 'm_mode', which is CRT_SPECIALIZE, where a kernel call can follow") !=
              std::string::npos);
    }
  }
  const struct
  {
    const char* what;
    std::string type, kernelWrite, between;
    std::string where, message, hint;
  } errors[] = {
      {"written by a kernel", "int", "m_last = 1u;", "", "Modes.cpp:5:10: error: ", "kernel 'kernel1D_Scale' writes member 'm_last', which is CRT_SPECIALIZE",
       "set it on the host before calling the control function"},
      {"changed between kernel calls", "int", "", "m_flip = !m_flip;", "Modes.cpp:3:",
       "control function 'Twice' changes member 'm_flip', which is CRT_SPECIALIZE, where a kernel call can follow", "set it before calling 'Twice'"},
      {"of a type no specialization constant holds", "double", "", "", "Modes.h:10:", "member 'm_mode' is CRT_SPECIALIZE but of type 'double'",
       "CRT_SPECIALIZE takes a bool, int, uint32_t, float or enum member"},
  };
  for (const auto& e : errors)
  {
    SECTION(e.what)
    {
      TempClass tc("Modes", header(e.type), source(e.kernelWrite, e.between));
      CommandResult r = translate(tc, "vulkan");
      INFO(r.output);
      REQUIRE_FALSE(r.crashed);
      REQUIRE(r.exitCode == 1);
      REQUIRE(r.output.find(e.where) != std::string::npos);
      REQUIRE(r.output.find(e.message) != std::string::npos);
      REQUIRE(r.output.find("note: hint: " + e.hint) != std::string::npos);
      REQUIRE_FALSE(fs::exists(tc.dir / "out_vulkan"));
      // A rule of the GPU's pipelines: the CPU and ISPC classes read the member as any other.
      for (const char* backend : {"cpu", "ispc"})
      {
        CommandResult other = translate(tc, backend);
        INFO(backend << ": " << other.output);
        REQUIRE(other.exitCode == 0);
        REQUIRE(other.output.find("CRT_SPECIALIZE") == std::string::npos);
      }
    }
  }
}

TEST_CASE("A control function that is not virtual translates with a warning, and the generated one hides it", "[diagnostics]")
{
  TempClass tc("NotVirtual", R"(#pragma once
class NotVirtual
{
public:
  void Run(int n, [[crossrt::size("n")]] float* out);
protected:
  void kernel1D_Fill(int n, float* out);
};
)",
               R"(#include "NotVirtual.h"
void NotVirtual::Run(int n, float* out) { kernel1D_Fill(n, out); }
void NotVirtual::kernel1D_Fill(int n, float* out) { for (int i = 0; i < n; i++) out[i] = 1.0f; }
)");
  CommandResult r = RunCrossrt("translate --class NotVirtual --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                               tc.Source("NotVirtual") + " --templates " CROSSRT_SOURCE_DIR "/templates");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  REQUIRE(r.output.find("NotVirtual.h:5:8: warning: control function 'Run' is not virtual") != std::string::npos);
  REQUIRE(r.output.find("hint: declare it 'virtual' in NotVirtual") != std::string::npos);
  std::ifstream header(tc.dir / "out" / "NotVirtual_Vulkan.h");
  const std::string text((std::istreambuf_iterator<char>(header)), std::istreambuf_iterator<char>());
  REQUIRE(text.find("  void Run(int n, float* out);\n") != std::string::npos);  // hides it: no override
  REQUIRE(text.find("virtual void RunCmd(VkCommandBuffer crt_cmd") != std::string::npos);
}

TEST_CASE("Host code that reads what kernels write runs after the last kernel, between kernels it is reported", "[diagnostics]")
{
  // m_total is a member reduction. The Vulkan class records the whole control function before any
  // kernel runs: read after the last kernel, it is read once the results are back; read between
  // two kernels, it would be the value from before the call.
  auto header = [](const char* name) {
    return std::string("#pragma once\nclass ") + name + R"(
{
public:
  virtual ~)" + name + R"(() = default;
  virtual void Run(int n, [[crossrt::size("n")]] const float* in, [[crossrt::size("n")]] float* out);
  float m_total = 0.0f, m_mean = 0.0f;
protected:
  void kernel1D_Sum(int n, const float* in);
  void kernel1D_Scale(int n, float s, const float* in, float* out);
};
)";
  };
  auto kernels = [](const char* name) {
    return std::string("void ") + name + "::kernel1D_Sum(int n, const float* in) { for (int i = 0; i < n; i++) m_total += in[i]; }\nvoid " + name +
           "::kernel1D_Scale(int n, float s, const float* in, float* out) { for (int i = 0; i < n; i++) out[i] = s * in[i]; }\n";
  };
  SECTION("after the last kernel: moved into Run, after the results are read back")
  {
    TempClass tc("Tail", header("Tail"), std::string(R"(#include "Tail.h"
void Tail::Run(int n, const float* in, float* out)
{
  m_total = 0.0f;
  kernel1D_Sum(n, in);
  kernel1D_Scale(n, 2.0f, in, out);
  m_mean = m_total / float(n);
}
)") + kernels("Tail"));
    CommandResult r = RunCrossrt("translate --class Tail --backend vulkan --out " + (tc.dir / "out").string() + " --source " + tc.Source("Tail") +
                                 " --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
    std::ifstream source(tc.dir / "out" / "Tail_Vulkan.cpp");
    const std::string text((std::istreambuf_iterator<char>(source)), std::istreambuf_iterator<char>());
    const size_t readBack = text.find("crt_self->crt_ReadPlainMembers();"), run = text.find("    crt_tail();\n");
    const size_t cmd = text.find("void Tail_Vulkan::RunCmd(");
    REQUIRE(readBack != std::string::npos);
    REQUIRE(run != std::string::npos);
    CHECK(readBack < run);  // Run runs the tail once the GPU's total is back
    // RunCmd stores it, with the parameter it reads, instead of running it while recording.
    CHECK(text.find("crt_hostTail_Run = [this, n]() mutable { m_mean = m_total / float(n); };", cmd) != std::string::npos);
    CHECK(text.find("crt_UpdateMemberCmd(crt_cmd, offsetof(ClassData, m_total)", cmd) != std::string::npos);  // the zeroing before stays
  }
  SECTION("between kernels: the recording is split there, with a note")
  {
    TempClass tc("Between", header("Between"), std::string(R"(#include "Between.h"
void Between::Run(int n, const float* in, float* out)
{
  m_total = 0.0f;
  kernel1D_Sum(n, in);
  kernel1D_Scale(n, 1.0f / m_total, in, out);
  if (m_total > 1.0f)
    kernel1D_Scale(n, 2.0f, in, out);
}
)") + kernels("Between"));
    CommandResult r = RunCrossrt("translate --class Between --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                                 tc.Source("Between") + " --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(r.output);
    REQUIRE_FALSE(r.crashed);
    REQUIRE(r.exitCode == 0);
    CHECK(r.output.find("Between.cpp:6:28: note: 'Run' reads 'm_total', which its kernels write, between kernel calls: on Vulkan the recording is split there") !=
          std::string::npos);
    std::ifstream source(tc.dir / "out" / "Between_Vulkan.cpp");
    const std::string text((std::istreambuf_iterator<char>(source)), std::istreambuf_iterator<char>());
    // A kernel's argument: the work before it runs first; a condition: the read waits.
    CHECK(text.find("crt_Synchronize(crt_cmd, \"Run\"), kernel1D_ScaleCmd(crt_cmd, n, 1.0f / m_total,") != std::string::npos);
    CHECK(text.find("if (crt_Synchronize(crt_cmd, \"Run\").m_total > 1.0f)") != std::string::npos);
    CHECK(text.find("crt_cmd = crt_self->crt_recording;") != std::string::npos);  // Run submits the last command buffer
    // The CPU classes run the body as written, in order: nothing to report, no note.
    CommandResult cpu = RunCrossrt("translate --class Between --backend cpu --out " + (tc.dir / "cpu").string() + " --source " +
                                   tc.Source("Between") + " --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(cpu.output);
    CHECK(cpu.exitCode == 0);
    CHECK(cpu.output.find("recording is split") == std::string::npos);
  }
  SECTION("an output parameter: an error between kernels, after the last one run once it is back")
  {
    TempClass tc("OutParam", header("OutParam"), std::string(R"(#include "OutParam.h"
void OutParam::Run(int n, const float* in, float* out)
{
  kernel1D_Scale(n, 2.0f, in, out);
  const float first = out[0];
  kernel1D_Scale(n, first, in, out);
  out[n - 1] = out[0] + 1.0f;
}
)") + kernels("OutParam"));
    CommandResult r = RunCrossrt("translate --class OutParam --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                                 tc.Source("OutParam") + " --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(r.output);
    REQUIRE(r.exitCode == 1);
    CHECK(r.output.find("OutParam.cpp:5:23: error: control function 'Run' uses 'out' between kernel calls") != std::string::npos);
    CHECK(r.output.find("OutParam.cpp:6:") == std::string::npos);  // handed to a kernel: no host use
    CHECK(r.output.find("OutParam.cpp:7:") == std::string::npos);  // after the last kernel: moved, not refused
  }
}

TEST_CASE("Member vectors on the host between kernel calls: element uses are synchronised on Vulkan, resizing is reported", "[diagnostics]")
{
  // The Vulkan class uploads member vectors when the call begins and reads back those its kernels
  // write when it ends. Host code between kernel calls that uses their elements gets the recording
  // split around it (wait, read back, upload); a resize, or a use inside a statement that also
  // records GPU work, cannot be split so and is an error. The CPU backends run it as written.
  const std::string header = R"(#pragma once
#include <vector>
class Counts
{
public:
  virtual ~Counts() = default;
  virtual void Run(int n);
  std::vector<int> m_in = std::vector<int>(64, 1), m_out = std::vector<int>(64), m_other = std::vector<int>(64);
  int m_first = 0;
protected:
  void kernel1D_Copy(int n);
  void kernel1D_Twice(int n);
};
)";
  const std::string kernels = R"(#include "Counts.h"
#include <utility>
void Counts::kernel1D_Copy(int n) { for (int i = 0; i < n; i++) m_out[i] = m_in[i]; }
void Counts::kernel1D_Twice(int n) { for (int i = 0; i < n; i++) m_out[i] = 2 * m_in[i]; }
)";
  // crossrt translate of Counts in `tc` for a backend, into a folder of that name.
  auto translate = [](const TempClass& tc, const std::string& backend) {
    return RunCrossrt("translate --class Counts --backend " + backend + " --out " + (tc.dir / backend).string() + " --source " + tc.Source("Counts") +
                      " --templates " CROSSRT_SOURCE_DIR "/templates");
  };
  SECTION("refused: a resize, and a read inside a statement that records GPU work")
  {
    TempClass tc("Counts", header, kernels + R"(void Counts::Run(int n)
{
  m_in[0] = 5;
  kernel1D_Copy(n);
  if (m_out[0] > 3) m_other[0] = 1;
  m_in.resize(n);
  std::swap(m_in, m_other);
  kernel1D_Twice(int(m_in.size()));
  if (m_out[1] > 0) kernel1D_Copy(n);
  m_first = m_out[0];
}
)");
    CommandResult r = translate(tc, "vulkan");
    INFO(r.output);
    REQUIRE_FALSE(r.crashed);
    REQUIRE(r.exitCode == 1);
    CHECK(r.output.find("Counts.cpp:7:3: error") == std::string::npos);   // an element written: uploaded after it
    CHECK(r.output.find("Counts.cpp:9:3: error") == std::string::npos);   // read back before it
    CHECK(r.output.find("Counts.cpp:10:3: error: control function 'Run' resizes 'm_in' before its last kernel call") != std::string::npos);
    CHECK(r.output.find("Counts.cpp:11:") == std::string::npos);   // a swap is translated
    CHECK(r.output.find("Counts.cpp:12:") == std::string::npos);   // size() and a kernel's argument are fine
    CHECK(r.output.find("Counts.cpp:13:7: error: control function 'Run' reads 'm_out' on the host in a statement that also records GPU work") !=
          std::string::npos);
    CHECK(r.output.find("use it in a statement of its own") != std::string::npos);
    CHECK(r.output.find("Counts.cpp:14:") == std::string::npos);   // after the last kernel: runs once m_out is back
    for (const char* backend : {"cpu", "ispc"}) {
      CommandResult cpu = translate(tc, backend);
      INFO(cpu.output);
      CHECK(cpu.exitCode == 0);
    }
  }
  SECTION("refused: a local reference or a lambda that reaches a vector after its statement")
  {
    TempClass tc("Counts", header, kernels + R"(void Counts::Run(int n)
{
  auto& in = m_in;
  kernel1D_Copy(n);
  in[0] = m_out[0];
  auto bump = [&]() { m_in[1] += 1; };
  bump();
  kernel1D_Twice(n);
}
)");
    CommandResult r = translate(tc, "vulkan");
    INFO(r.output);
    REQUIRE_FALSE(r.crashed);
    REQUIRE(r.exitCode == 1);
    CHECK(r.output.find("Counts.cpp:7:14: error: control function 'Run' lets host code reach 'm_in' between kernel calls through the local 'in'") !=
          std::string::npos);
    CHECK(r.output.find("Counts.cpp:10:23: error: control function 'Run' lets host code reach 'm_in' between kernel calls through a lambda") !=
          std::string::npos);
    CommandResult cpu = translate(tc, "cpu");
    CHECK(cpu.exitCode == 0);
  }
  SECTION("translated: the recording is split around each host statement, with a note")
  {
    TempClass tc("Counts", header, kernels + R"(void Counts::Run(int n)
{
  m_in[0] = 5;
  kernel1D_Copy(n);
  if (m_out[0] > 3) m_other[0] = m_out[1];
  for (int& v : m_in)
    v += 1;
  kernel1D_Twice(n);
  m_first = m_out[0];
}
)");
    CommandResult r = translate(tc, "vulkan");
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
    CHECK(r.output.find("Counts.cpp:9:3: note: 'Run' uses member vectors on the host between kernel calls: on Vulkan the recording is split before this statement "
                        "(the work recorded so far is submitted and waited for, and 'm_out' read back)") != std::string::npos);
    CHECK(r.output.find("Counts.cpp:10:3: note: 'Run' uses member vectors on the host between kernel calls") != std::string::npos);  // the loop: m_in uploaded after it
    std::ifstream source(tc.dir / "vulkan" / "Counts_Vulkan.cpp");
    const std::string text((std::istreambuf_iterator<char>(source)), std::istreambuf_iterator<char>());
    const size_t cmd = text.find("void Counts_Vulkan::RunCmd(");
    REQUIRE(cmd != std::string::npos);
    const size_t first = text.find("crt_Synchronize(crt_cmd, \"Run\");", cmd);
    const size_t copy = text.find("kernel1D_CopyCmd(", cmd);
    // Before the first kernel: the element written is uploaded after the statement.
    CHECK(first < copy);
    CHECK(text.find("crossrt::UploadVector(crt_vdata.m_in, m_in);", first) < copy);
    // Between the kernels: m_out read back before the statement; m_other only the host uses.
    const size_t read = text.find("crossrt::DownloadVector(crt_vdata.m_out, m_out);", copy);
    CHECK(read != std::string::npos);
    CHECK(read < text.find("if (m_out[0] > 3)", copy));
    CHECK(text.find("UploadVector(crt_vdata.m_other") == std::string::npos);
    CHECK(text.find("crossrt::UploadVector(crt_vdata.m_in, m_in);", read) < text.find("kernel1D_TwiceCmd(", cmd));
  }
}

TEST_CASE("kernel_slicer's block-expansion kernels are an error at the kernel, with a hint", "[diagnostics]")
{
  TempClass tc("Blocks", R"(#pragma once
class Blocks
{
public:
  virtual ~Blocks() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out);
protected:
  void kernelBE1D_Fill(int n, float* out);
};
)",
               R"(#include "Blocks.h"
void Blocks::kernelBE1D_Fill(int n, float* out) { for (int i = 0; i < n; i++) out[i] = 1.0f; }
void Blocks::Run(int n, float* out) { kernelBE1D_Fill(n, out); }
)");
  CommandResult r = RunCrossrt("translate --class Blocks --backend vulkan --out " + (tc.dir / "out").string() + " --source " + tc.Source("Blocks") +
                               " --templates " CROSSRT_SOURCE_DIR "/templates");
  INFO(r.output);
  REQUIRE_FALSE(r.crashed);
  REQUIRE(r.exitCode != 0);
  CHECK(r.output.find("Blocks.h:8:8: error: 'kernelBE1D_Fill' is one of kernel_slicer's block-expansion kernels") != std::string::npos);
  CHECK(r.output.find("hint: the CPU backend runs it, a block per core; here write it as a kernel1D_ loop") != std::string::npos);
  // As kernel_slicer's test 030 writes it: a template over the block size, which is not a method
  // until it is instantiated (it was "class has no kernels", with no line).
  TempClass templated("BlockSizes", R"(#pragma once
class BlockSizes
{
public:
  virtual ~BlockSizes() = default;
  virtual void Run(unsigned n, [[crossrt::size("n")]] float* out);
  template <unsigned bsize>
  void kernelBE1D_Fill(unsigned blocks, float* out);
};
)",
                      R"(#include "BlockSizes.h"
template <unsigned bsize>
void BlockSizes::kernelBE1D_Fill(unsigned blocks, float* out) { for (unsigned b = 0; b < blocks; b++) for (unsigned i = 0; i < bsize; i++) out[b * bsize + i] = 1.0f; }
void BlockSizes::Run(unsigned n, float* out) { kernelBE1D_Fill<64>(n / 64, out); }
)");
  for (const char* backend : {"vulkan", "ispc", "cpu"})  // the CPU backend runs a block per core (test_block_kernels.cpp)
  {
    CommandResult t = RunCrossrt("translate --class BlockSizes --backend " + std::string(backend) + " --out " + (templated.dir / backend).string() +
                                 " --source " + templated.Source("BlockSizes") + " --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(backend << ": " << t.output);
    REQUIRE_FALSE(t.crashed);
    if (std::string(backend) == "cpu")
    {
      REQUIRE(t.exitCode == 0);
      continue;
    }
    REQUIRE(t.exitCode != 0);
    CHECK(t.output.find("BlockSizes.h:8:8: error: 'kernelBE1D_Fill' is one of kernel_slicer's block-expansion kernels") != std::string::npos);
    CHECK(t.output.find("the CPU backend runs it") != std::string::npos);
  }
}

TEST_CASE("Locals reduced in a loop nest may only be reduced there, one way, and read after it", "[diagnostics]")
{
  // Line 8 of Sums.cpp is the loop body's statement.
  struct LocalCase { const char* name; const char* statement; const char* message; const char* hint; };
  const LocalCase cases[] = {
      {"read in the loop", "    sum += data[i]; data[i] = sum;", "the loop of kernel 'kernel1D_Sum' reads 'sum', which its iterations reduce",
       "read it in the statements after the loop nest"},
      {"two operations", "    sum += data[i]; sum = std::max(sum, data[i]);", "local 'sum' is reduced with two different operations in one loop nest",
       "use one of +=, -=, min or max per variable"},
      {"a plain store", "    sum = data[i];", "the loop of kernel 'kernel1D_Sum' writes 'sum', declared before the loop",
       "x = std::max(x, v)"},
  };
  for (const LocalCase& c : cases)
  {
    SECTION(c.name)
    {
      TempClass tc("Sums", R"(#pragma once
class Sums
{
public:
  virtual ~Sums() = default;
  virtual void Sum(int n, [[crossrt::size("n")]] float* data, [[crossrt::size(1)]] float* total);
protected:
  void kernel1D_Sum(int n, float* data, float* total);
};
)",
                   std::string(R"(#include "Sums.h"
#include <algorithm>
void Sums::Sum(int n, float* data, float* total) { kernel1D_Sum(n, data, total); }
void Sums::kernel1D_Sum(int n, float* data, float* total)
{
  float sum = 0.0f;
  for (int i = 0; i < n; i++) {
)") + c.statement + "\n  }\n  total[0] = sum;\n}\n");
      CommandResult r = RunCrossrt("translate --class Sums --backend vulkan --out " + (tc.dir / "out").string() + " --source " + tc.Source("Sums") +
                                   " --templates " CROSSRT_SOURCE_DIR "/templates");
      INFO(r.output);
      REQUIRE_FALSE(r.crashed);
      REQUIRE(r.exitCode == 1);
      REQUIRE(r.output.find(tc.Source("Sums") + ":8:") != std::string::npos);
      REQUIRE(r.output.find(c.message) != std::string::npos);
      REQUIRE(r.output.find(c.hint) != std::string::npos);
    }
  }
}

TEST_CASE("A statement before a loop nest that sets a local and does more is refused, one that only sets locals is not", "[diagnostics]")
{
  const char* header = R"(#pragma once
#include "LiteMath.h"
class Scales
{
public:
  virtual ~Scales() = default;
  virtual void Scale(int n, [[crossrt::size("n")]] float* data);
  float m_step = 1.0f;
protected:
  float NextStep() { m_step *= 2.0f; return m_step; }
  void kernel1D_Scale(int n, float* data);
};
)";
  // Line 6 of Scales.cpp is the statement before the loop nest.
  for (const bool onlyLocals : {true, false})
  {
    SECTION(onlyLocals ? "only locals" : "a local and a member")
    {
      TempClass tc("Scales", header, std::string(R"(#include "Scales.h"
void Scales::Scale(int n, float* data) { kernel1D_Scale(n, data); }
void Scales::kernel1D_Scale(int n, float* data)
{
  LiteMath::float2 s(1.0f, 0.0f);
)") + (onlyLocals ? "  s[1] = m_step * 3.0f;" : "  s[1] = NextStep();") + R"(
  for (int i = 0; i < n; i++)
    data[i] *= s.x + s.y;
}
)");
      CommandResult r = RunCrossrt("translate --class Scales --backend vulkan --out " + (tc.dir / "out").string() + " --source " + tc.Source("Scales") +
                                   " --templates " CROSSRT_SOURCE_DIR "/templates -- -I" CROSSRT_SOURCE_DIR "/libs/litemath");
      INFO(r.output);
      REQUIRE_FALSE(r.crashed);
      if (onlyLocals)
      {
        REQUIRE(r.exitCode == 0);
        std::ifstream shader(tc.dir / "out" / "shaders" / "kernel1D_Scale.comp");
        const std::string text((std::istreambuf_iterator<char>(shader)), std::istreambuf_iterator<char>());
        REQUIRE(text.find("  s[1] = m_step * 3.0;\n  data[i] *= s.x + s.y;") != std::string::npos);  // every thread sets it
        continue;
      }
      REQUIRE(r.exitCode == 1);
      REQUIRE(r.output.find(tc.Source("Scales") + ":6:") != std::string::npos);
      REQUIRE(r.output.find("a statement before the loop nest of kernel 'kernel1D_Scale' changes 's'") != std::string::npos);
      REQUIRE(r.output.find("split it") != std::string::npos);
    }
  }
}

TEST_CASE("A source that does not parse passes the compiler's diagnostics through", "[diagnostics]")
{
  TempClass tc("Broken", "#pragma once\nclass Broken { public: virtual void Run(); };\n",
               "#include \"Broken.h\"\nvoid Broken::Run() { int x = ; }\n");
  CommandResult r = RunCrossrt("translate --class Broken --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                               tc.Source("Broken") + " --templates " CROSSRT_SOURCE_DIR "/templates");
  INFO(r.output);
  REQUIRE(r.exitCode == 1);
  REQUIRE(r.output.find("Broken.cpp:2:30: error: expected expression") != std::string::npos);
}

TEST_CASE("Bad command lines get a usage message", "[diagnostics]")
{
  CommandResult r = RunCrossrt("translate --class X --backend metal --out /tmp/x --source /tmp/x.cpp");
  REQUIRE(r.exitCode == 2);
  REQUIRE(r.output.find("--backend must be 'vulkan', 'cpu' or 'ispc'") != std::string::npos);
  r = RunCrossrt("translate --class X --backend cpu --out /tmp/x --source /nonexistent/x.cpp");
  REQUIRE(r.exitCode == 1);
  REQUIRE(r.output.find("source file '/nonexistent/x.cpp' does not exist") != std::string::npos);
}

TEST_CASE("A by-value kernel parameter whose C++ layout differs on the GPU is reported", "[diagnostics]")
{
  TempClass tc("Flags", R"(#pragma once
class Flags
{
public:
  virtual ~Flags() = default;
  virtual void Run(int n, bool invert, [[crossrt::size("n")]] float* out);
protected:
  void kernel1D_Fill(int n, bool invert, float* out);
};
)",
               R"(#include "Flags.h"
void Flags::Run(int n, bool invert, float* out) { kernel1D_Fill(n, invert, out); }
void Flags::kernel1D_Fill(int n, bool invert, float* out) { for (int i = 0; i < n; i++) out[i] = invert ? -1.0f : 1.0f; }
)");
  CommandResult r = RunCrossrt("translate --class Flags --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                               tc.Source("Flags") + " --templates " CROSSRT_SOURCE_DIR "/templates");
  INFO(r.output);
  REQUIRE(r.exitCode == 1);
  REQUIRE(r.output.find("Flags.h:8:34: error: kernel parameter 'invert' of type 'bool' cannot be passed to the GPU") != std::string::npos);
  REQUIRE(r.output.find("use int") != std::string::npos);
}

TEST_CASE("A std::sort the GPU cannot do yet is reported, not run on a stale host copy", "[diagnostics]")
{
  struct Case { const char* call; const char* message; };
  const Case cases[] = {
      {"std::sort(m_keys.begin(), m_keys.end(), [](uint32_t a, uint32_t b) { return (a & 255u) < (b & 255u); });",
       "the GPU sort understands comparators of the form `[](T a, T b) { return a.key < b.key; }`"},
      {"std::sort(m_pairs.begin(), m_pairs.end(), [](Pair a, Pair b) { return a.k < b.k || (a.k == b.k && a.v < b.v); });",
       "the GPU sort understands comparators of the form"},
      {"std::sort(m_pairs.begin(), m_pairs.end());", "sorting elements without a comparator needs uint32_t, int or float elements"},
      {"std::sort(m_keys.begin(), m_other.end());", "first and last must belong to the same buffer"},
  };
  for (const Case& c : cases)
  {
    INFO(c.call);
    TempClass tc("Sorter", R"(#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>
struct Pair { uint32_t k, v; };
inline bool operator<(Pair a, Pair b) { return a.k < b.k; }
class Sorter
{
public:
  virtual ~Sorter() = default;
  virtual void Run(int n);
  std::vector<uint32_t> m_keys, m_other;
  std::vector<Pair> m_pairs;
protected:
  void kernel1D_Fill(int n);
};
)",
                 std::string(R"(#include "Sorter.h"
void Sorter::Run(int n)
{
  kernel1D_Fill(n);
  )") + c.call + R"(
}
void Sorter::kernel1D_Fill(int n) { for (int i = 0; i < n; i++) m_keys[i] = uint32_t(i * 7 % 13); }
)");
    CommandResult r = RunCrossrt("translate --class Sorter --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                                 tc.Source("Sorter") + " --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(r.output);
    REQUIRE(r.exitCode == 1);
    REQUIRE(r.output.find("Sorter.cpp:5:3: error: 'std::sort' on device data: ") != std::string::npos);
    REQUIRE(r.output.find(c.message) != std::string::npos);
    REQUIRE(r.output.find("hint:") != std::string::npos);
    REQUIRE(!std::filesystem::exists(tc.dir / "out" / "Sorter_Vulkan.cpp"));
  }
}

TEST_CASE("Calls through an interface need a composed implementation whose code and data the GPU can reach", "[diagnostics]")
{
  // Tracer calls IShape through a shared_ptr; Spheres implements it in Spheres.cpp.
  TempClass tc("Tracer", R"(#pragma once
#include "LiteMath.h"
#include <memory>
#include <vector>
struct IShape
{
  virtual ~IShape() = default;
  virtual float Distance(LiteMath::float3 p) = 0;
};
class Spheres : public IShape
{
public:
  float Distance(LiteMath::float3 p) override;
  std::vector<LiteMath::float4> m_spheres;
private:
  std::vector<float> m_hidden;
};
class Tracer
{
public:
  virtual ~Tracer() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out);
  std::shared_ptr<IShape> m_shape;
protected:
  void kernel1D_Run(int n, float* out);
};
)",
               R"(#include "Tracer.h"
void Tracer::Run(int n, float* out) { kernel1D_Run(n, out); }
void Tracer::kernel1D_Run(int n, float* out)
{
  for (int i = 0; i < n; i++)
    out[i] = m_shape->Distance(LiteMath::float3(float(i), 0.0f, 0.0f));
}
)");
  auto writeSpheres = [&](const char* body) { std::ofstream(tc.dir / "Spheres.cpp") << "#include \"Tracer.h\"\n" << body; };
  const std::string base = "translate --class Tracer --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                           tc.Source("Tracer") + " --templates " CROSSRT_SOURCE_DIR "/templates";
  const std::string args = " -- -I" CROSSRT_SOURCE_DIR "/libs/litemath -I" + tc.dir.string();
  const std::string spheres = " --source " + (tc.dir / "Spheres.cpp").string();

  SECTION("no implementation named")
  {
    CommandResult r = RunCrossrt(base + args);
    INFO(r.output);
    REQUIRE(r.exitCode == 1);
    REQUIRE(r.output.find("Tracer.cpp:6:14: error: call of IShape::Distance through member 'm_shape' in a kernel, but no "
                          "implementation of IShape is composed into the class") != std::string::npos);
    REQUIRE(r.output.find("hint: name the implementation the GPU runs: crossrt_add_class(... COMPOSE IShape=<Implementation>)") != std::string::npos);
  }
  SECTION("the implementation's source is missing")
  {
    CommandResult r = RunCrossrt(base + " --compose IShape=Spheres" + args);
    INFO(r.output);
    REQUIRE(r.exitCode == 1);
    REQUIRE(r.output.find("composed as Spheres, but no source file defines class Spheres with the bodies of the methods they call") != std::string::npos);
    REQUIRE(r.output.find("hint: list the implementation's source file") != std::string::npos);
  }
  SECTION("the implementation reads a private member")
  {
    writeSpheres("float Spheres::Distance(LiteMath::float3 p)\n{\n  return LiteMath::length(p - LiteMath::to_float3(m_spheres[0])) - m_hidden[0];\n}\n");
    CommandResult r = RunCrossrt(base + spheres + " --compose IShape=Spheres" + args);
    INFO(r.output);
    REQUIRE(r.exitCode == 1);
    REQUIRE(r.output.find("Tracer.h:16:22: error: member 'm_hidden' of Spheres is read on the GPU through composition") != std::string::npos);
    REQUIRE(r.output.find("hint: declare it public") != std::string::npos);
  }
  SECTION("the implementation writes its own member")
  {
    writeSpheres("float Spheres::Distance(LiteMath::float3 p)\n{\n  m_spheres[0].w += 1.0f;\n  return LiteMath::length(p) - m_spheres[0].w;\n}\n");
    CommandResult r = RunCrossrt(base + spheres + " --compose IShape=Spheres" + args);
    INFO(r.output);
    REQUIRE(r.exitCode == 1);
    REQUIRE(r.output.find("Spheres.cpp:4:18: error: composed code writes member 'm_spheres' of Spheres, whose GPU copy is never read back") != std::string::npos);
    REQUIRE(r.output.find("hint: members of a composed implementation are read-only in kernels") != std::string::npos);
  }
  SECTION("a malformed composition is a usage error")
  {
    CommandResult r = RunCrossrt(base + " --compose IShape" + args);
    INFO(r.output);
    REQUIRE(r.exitCode == 2);
    REQUIRE(r.output.find("--compose takes Interface=Implementation") != std::string::npos);
  }
  REQUIRE(!std::filesystem::exists(tc.dir / "out" / "Tracer_Vulkan.cpp"));
}

TEST_CASE("Appends that a backend cannot make safe, or whose count the host does not have yet, are reported", "[diagnostics][append]")
{
  // Each case: Appender's extra declarations, then Appender.cpp from its line 2 on.
  struct Case { const char* name; const char* declarations; const char* source; int line; const char* message; const char* hint; };
  const Case cases[] = {
      {"a helper that appends calls a private member function", "  uint32_t Push(uint32_t i);\nprivate:\n  uint32_t Twice(uint32_t i) const { return 2 * i; }",
       "void Appender::Run(int n, const float* in) { kernel1D_Find(n, in); }\n"
       "uint32_t Appender::Push(uint32_t i) { m_hits.push_back(Twice(i)); return i; }\n"
       "void Appender::kernel1D_Find(int n, const float* in)\n{\n  for (int i = 0; i < n; i++)\n    if (in[i] > 0.0f) Push(uint32_t(i));\n}\n",
       3, "'Push' appends to a member vector, so the CPU backend copies it into the derived class, but it uses private member 'Twice'",
       "declare 'Twice' protected"},
      {"sorting part of an appended vector", "",
       "#include <algorithm>\n"
       "void Appender::Run(int n, const float* in) { kernel1D_Find(n, in); std::sort(m_hits.begin() + 1, m_hits.end()); }\n"
       "void Appender::kernel1D_Find(int n, const float* in)\n{\n  for (int i = 0; i < n; i++)\n    if (in[i] > 0.0f) m_hits.push_back(uint32_t(i));\n}\n",
       3, "'std::sort' on device data: 'm_hits' is appended to by kernels, so its size is known only on the GPU: sort all of it, from begin() to end()",
       "use member std::vector begin()/end()/data()"},
      {"a kernel reads the size it appends to", "",
       "void Appender::Run(int n, const float* in) { kernel1D_Find(n, in); }\n"
       "void Appender::kernel1D_Find(int n, const float* in)\n{\n  for (int i = 0; i < n; i++)\n"
       "    if (in[i] > float(m_hits.size())) m_hits.push_back(uint32_t(i));\n}\n",
       6, "kernel 'kernel1D_Find' reads the size of 'm_hits', which it appends to", "the final size is known after the kernel"},
      {"the control function reads the appended size", "  void kernel1D_Use(int count);",
       "void Appender::Run(int n, const float* in) { kernel1D_Find(n, in); kernel1D_Use(int(m_hits.size())); }\n"
       "void Appender::kernel1D_Find(int n, const float* in)\n{\n  for (int i = 0; i < n; i++)\n    if (in[i] > 0.0f) m_hits.push_back(uint32_t(i));\n}\n"
       "void Appender::kernel1D_Use(int count)\n{\n  for (int i = 0; i < count; i++) m_out[i] = float(m_hits[i]);\n}\n",
       2, "control function 'Run' uses size() of 'm_hits', which kernels append to: on the GPU its size and contents are known only after the call returns",
       "loop to m_hits.size() inside a kernel1D_ kernel (dispatched indirectly"},
      {"a 2D loop nest over an appended vector", "  void kernel2D_Use(int w);",
       "void Appender::Run(int n, const float* in) { kernel1D_Find(n, in); kernel2D_Use(4); }\n"
       "void Appender::kernel1D_Find(int n, const float* in)\n{\n  for (int i = 0; i < n; i++)\n    if (in[i] > 0.0f) m_hits.push_back(uint32_t(i));\n}\n"
       "void Appender::kernel2D_Use(int w)\n{\n  for (uint32_t y = 0; y < m_hits.size(); y++)\n    for (int x = 0; x < w; x++) m_out[y * 4 + x] = 1.0f;\n}\n",
       10, "kernel 'kernel2D_Use' loops to the size of 'm_hits', which kernels append to on the GPU, in a 2D loop nest",
       "loop to m_hits.size() in a kernel1D_ kernel"},
      {"a loop over an appended vector that does not start at 0", "  void kernel1D_Use();",
       "void Appender::Run(int n, const float* in) { kernel1D_Find(n, in); kernel1D_Use(); }\n"
       "void Appender::kernel1D_Find(int n, const float* in)\n{\n  for (int i = 0; i < n; i++)\n    if (in[i] > 0.0f) m_hits.push_back(uint32_t(i));\n}\n"
       "void Appender::kernel1D_Use()\n{\n  for (uint32_t i = 1; i < m_hits.size(); i++) m_out[i] = float(m_hits[i]);\n}\n",
       10, "kernel 'kernel1D_Use' loops over 'm_hits', which kernels append to on the GPU, but not from 0 to m_hits.size()",
       "skip elements inside the loop"},
      {"a reduction in a kernel dispatched indirectly", "  void kernel1D_Use();",
       "void Appender::Run(int n, const float* in) { kernel1D_Find(n, in); kernel1D_Use(); }\n"
       "void Appender::kernel1D_Find(int n, const float* in)\n{\n  for (int i = 0; i < n; i++)\n    if (in[i] > 0.0f) m_hits.push_back(uint32_t(i));\n}\n"
       "void Appender::kernel1D_Use()\n{\n  for (uint32_t i = 0; i < m_hits.size(); i++) m_sum += float(m_hits[i]);\n}\n",
       -1, "kernel 'kernel1D_Use' reduces members and is dispatched indirectly (it loops to m_hits.size())",
       "append the values and reduce them in a later kernel"},
  };
  for (const Case& c : cases)
  {
    SECTION(c.name)
    {
      TempClass tc("Appender", std::string(R"(#pragma once
#include <cstdint>
#include <vector>
class Appender
{
public:
  virtual ~Appender() = default;
  virtual void Run(int n, [[crossrt::size("n")]] const float* in);
  std::vector<uint32_t> m_hits;
  std::vector<float> m_out;
  float m_sum = 0.0f;
protected:
  void kernel1D_Find(int n, const float* in);
)") + c.declarations + "\n};\n",
                   std::string("#include \"Appender.h\"\n") + c.source);
      CommandResult r = RunCrossrt("translate --class Appender --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                                   tc.Source("Appender") + " --templates " CROSSRT_SOURCE_DIR "/templates");
      INFO(r.output);
      REQUIRE_FALSE(r.crashed);
      REQUIRE(r.exitCode == 1);
      // The reduction case points at the kernel's declaration in the header.
      const std::string where = c.line > 0 ? "Appender.cpp:" + std::to_string(c.line) + ":" : std::string("Appender.h:");
      REQUIRE(r.output.find(where) != std::string::npos);
      REQUIRE(r.output.find(std::string("error: ") + c.message) != std::string::npos);
      REQUIRE(r.output.find(std::string("hint: ")) != std::string::npos);
      REQUIRE(r.output.find(c.hint) != std::string::npos);
      REQUIRE(!std::filesystem::exists(tc.dir / "out" / "Appender_Vulkan.cpp"));
    }
  }
}

TEST_CASE("Virtual calls whose implementations the GPU cannot run are reported", "[diagnostics][virtual]")
{
  struct Case { const char* name; const char* impls; const char* call; const char* file; const char* message; const char* hint; };
  const Case cases[] = {
      {"a member that is not plain data", "struct Polygon : IShape { std::vector<float> xs; float Area() const override { return 0.0f; } };\n",
       "Area()", "Areas.h:", "member 'xs' of Polygon cannot be copied to the GPU", "objects called through virtual functions hold plain data"},
      {"no implementation", "", "Area()", "Areas.h:", "kernels call IShape through 'm_shapes', but no class that implements it is defined here",
       "define the implementations"},
      {"a non-virtual method", "struct Square : IShape { float side = 1.0f; float Area() const override { return side * side; } };\n",
       "Scale()", "Areas.cpp:", "call of the non-virtual IShape::Scale through 'm_shapes' in a kernel", "make the method virtual"},
      {"a body the translator cannot see", "struct Square : IShape { float side = 1.0f; float Area() const override; };\n",
       "Area()", "Areas.h:", "the GPU needs the body of Square's Area", "define it in the header that declares Square"},
  };
  for (const Case& c : cases)
  {
    SECTION(c.name)
    {
      TempClass tc("Areas", std::string(R"(#pragma once
#include <memory>
#include <vector>
struct IShape
{
  virtual ~IShape() = default;
  virtual float Area() const = 0;
  float Scale() const { return 1.0f; }
};
)") + c.impls + R"(class Areas
{
public:
  virtual ~Areas() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out);
  std::vector<std::shared_ptr<IShape>> m_shapes;
protected:
  void kernel1D_Run(int n, float* out);
};
)",
                   std::string(R"(#include "Areas.h"
void Areas::Run(int n, float* out) { kernel1D_Run(n, out); }
void Areas::kernel1D_Run(int n, float* out)
{
  for (int i = 0; i < n; i++)
    out[i] = m_shapes[i]->)") + c.call + ";\n}\n");
      CommandResult r = RunCrossrt("translate --class Areas --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                                   tc.Source("Areas") + " --templates " CROSSRT_SOURCE_DIR "/templates");
      INFO(r.output);
      REQUIRE_FALSE(r.crashed);
      REQUIRE(r.exitCode == 1);
      REQUIRE(std::regex_search(r.output, std::regex(std::string(c.file) + R"(\d+:\d+: error: )")));
      REQUIRE(r.output.find(std::string("error: ") + c.message) != std::string::npos);
      REQUIRE(r.output.find(std::string("hint: ")) != std::string::npos);
      REQUIRE(r.output.find(c.hint) != std::string::npos);
      REQUIRE(!std::filesystem::exists(tc.dir / "out" / "Areas_Vulkan.cpp"));
    }
  }
  SECTION("a private member: read through a member pointer an explicit instantiation hands out")
  {
    TempClass tc("Areas", R"(#pragma once
#include <memory>
#include <vector>
struct IShape
{
  virtual ~IShape() = default;
  virtual float Area() const = 0;
};
class Square : public IShape
{
public:
  float Area() const override { return side * side; }
private:
  float side = 1.0f;
};
class Areas
{
public:
  virtual ~Areas() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out);
  std::vector<std::shared_ptr<IShape>> m_shapes;
protected:
  void kernel1D_Run(int n, float* out);
};
)",
                 R"(#include "Areas.h"
void Areas::Run(int n, float* out) { kernel1D_Run(n, out); }
void Areas::kernel1D_Run(int n, float* out)
{
  for (int i = 0; i < n; i++)
    out[i] = m_shapes[i]->Area();
}
)");
    CommandResult r = RunCrossrt("translate --class Areas --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                                 tc.Source("Areas") + " --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
    std::ifstream source(tc.dir / "out" / "Areas_Vulkan.cpp");
    const std::string text((std::istreambuf_iterator<char>(source)), std::istreambuf_iterator<char>());
    CHECK(text.find("template struct MemberOf<Square_side, &Square::side>;") != std::string::npos);
    CHECK(text.find("std::memcpy(&to.side, &(from.*PointerTo(Square_side{})), sizeof(to.side));") != std::string::npos);
  }
  SECTION("the size of a vector of objects read without calling through it")
  {
    TempClass tc("Counts", R"(#pragma once
#include <memory>
#include <vector>
struct IShape { virtual ~IShape() = default; virtual float Area() const = 0; };
struct Square : IShape { float side = 1.0f; float Area() const override { return side * side; } };
class Counts
{
public:
  virtual ~Counts() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out);
  std::vector<std::shared_ptr<IShape>> m_shapes;
protected:
  void kernel1D_Run(int n, float* out);
};
)",
                 "#include \"Counts.h\"\nvoid Counts::Run(int n, float* out) { kernel1D_Run(n, out); }\n"
                 "void Counts::kernel1D_Run(int n, float* out)\n{\n  for (int i = 0; i < n; i++)\n    out[i] = float(m_shapes.size());\n}\n");
    CommandResult r = RunCrossrt("translate --class Counts --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                                 tc.Source("Counts") + " --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(r.output);
    REQUIRE_FALSE(r.crashed);
    REQUIRE(r.exitCode == 1);
    REQUIRE(r.output.find("Counts.cpp:6:20: error: the kernel reads the size of 'm_shapes', a vector of objects it calls no virtual function through") !=
            std::string::npos);
    REQUIRE(r.output.find("hint: keep the count in a plain member") != std::string::npos);
  }
  SECTION("a class in two vectors whose slots differ at level 1")
  {
    TempClass tc("Slots", R"(#pragma once
#include <memory>
#include <vector>
struct IArea { virtual ~IArea() = default; virtual float Area() const = 0; };
struct IMass { virtual ~IMass() = default; virtual float Mass() const = 0; };
struct Dot : IArea, IMass { float r = 1.0f; float Area() const override { return r; } float Mass() const override { return r; } };
struct Quad : IArea { float a = 1.0f, b = 1.0f, c, d, e, f, g, h; float Area() const override { return a * b; } };
class Slots
{
public:
  virtual ~Slots() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out);
  std::vector<std::shared_ptr<IArea>> m_areas;
  std::vector<std::shared_ptr<IMass>> m_masses;
protected:
  void kernel1D_Run(int n, float* out);
};
)",
                 "#include \"Slots.h\"\nvoid Slots::Run(int n, float* out) { kernel1D_Run(n, out); }\n"
                 "void Slots::kernel1D_Run(int n, float* out)\n{\n  for (int i = 0; i < n; i++)\n    out[i] = m_areas[i]->Area() + m_masses[i]->Mass();\n}\n");
    CommandResult r = RunCrossrt("translate --class Slots --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                                 tc.Source("Slots") + " --virtual-level 1 --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(r.output);
    REQUIRE_FALSE(r.crashed);
    REQUIRE(r.exitCode == 1);
    REQUIRE(r.output.find("error: at virtual-function level 1, Dot takes a 16-byte slot in 'm_masses' but a 32-byte slot in 'm_areas'") != std::string::npos);
    REQUIRE(r.output.find("hint: use level 2") != std::string::npos);
    // Level 2 has no slots: the same class translates.
    r = RunCrossrt("translate --class Slots --backend vulkan --out " + (tc.dir / "out").string() + " --source " + tc.Source("Slots") +
                   " --virtual-level 2 --templates " CROSSRT_SOURCE_DIR "/templates");
    REQUIRE(r.exitCode == 0);
  }
  SECTION("a level that does not exist is a usage error")
  {
    TempClass tc("Areas", "#pragma once\nclass Areas {};\n", "#include \"Areas.h\"\n");
    CommandResult r = RunCrossrt("translate --class Areas --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                                 tc.Source("Areas") + " --virtual-level 4 --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(r.output);
    REQUIRE(r.exitCode == 2);
    REQUIRE(r.output.find("--virtual-level takes 1 (one array of equal slots), 2 (a buffer per class) or 3 (2, plus callable and intersection shaders), not '4'") !=
            std::string::npos);
  }
}

TEST_CASE("The --name option names the generated class, its files and its global symbols", "[diagnostics][name]")
{
  TempClass tc("Filler", R"(#pragma once
class Filler {
public:
  virtual ~Filler() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out);
protected:
  void kernel1D_Fill(int n, float* out);
};
)",
               R"(#include "Filler.h"
void Filler::Run(int n, float* out) { kernel1D_Fill(n, out); }
void Filler::kernel1D_Fill(int n, float* out) { for (int i = 0; i < n; i++) out[i] = 1.0f; }
)");
  auto read = [&](const char* name) {
    std::ifstream file(tc.dir / "out" / name);
    return std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  };
  SECTION("Vulkan")
  {
    CommandResult r = RunCrossrt("translate --class Filler --backend vulkan --name FillerOnGpu --out " + (tc.dir / "out").string() +
                                 " --source " + tc.Source("Filler") + " --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
    REQUIRE_FALSE(std::filesystem::exists(tc.dir / "out" / "Filler_Vulkan.h"));
    const std::string header = read("FillerOnGpu.h"), source = read("FillerOnGpu.cpp"), spirv = read("FillerOnGpu_shaders.cpp");
    CHECK(header.find("class FillerOnGpu : public Filler") != std::string::npos);
    CHECK(header.find("std::shared_ptr<Filler> CreateFillerOnGpu(") != std::string::npos);
    CHECK(source.find("FillerOnGpu_kernel1D_Fill_spv") != std::string::npos);
    CHECK(spirv.find("const uint32_t FillerOnGpu_kernel1D_Fill_spv[]") != std::string::npos);
    CHECK(spirv.find("Filler_kernel1D_Fill_spv") == std::string::npos);
  }
  SECTION("CPU")
  {
    CommandResult r = RunCrossrt("translate --class Filler --backend cpu --name FillerOnCores --out " + (tc.dir / "out").string() +
                                 " --source " + tc.Source("Filler") + " --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
    CHECK(read("FillerOnCores.h").find("class FillerOnCores : public Filler") != std::string::npos);
    CHECK(read("FillerOnCores.cpp").find("void FillerOnCores::Run(") != std::string::npos);
  }
  SECTION("a name that is not an identifier is a usage error")
  {
    CommandResult r = RunCrossrt("translate --class Filler --backend vulkan --name 2Fill --out " + (tc.dir / "out").string() + " --source " +
                                 tc.Source("Filler") + " --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(r.output);
    REQUIRE(r.exitCode == 2);
    REQUIRE(r.output.find("--name takes a C++ identifier (the generated class's name), not '2Fill'") != std::string::npos);
  }
}

TEST_CASE("Image uses the GPU cannot make are reported", "[diagnostics][images]")
{
  struct Case { const char* name; const char* body; const char* message; const char* hint; };
  const Case cases[] = {
      {"a part of a texel written", "m_image[LiteMath::int2(i, 0)].x = 1.0f;", "kernel writes part of a texel of Image2D member 'm_image'",
       "GPU images store whole texels"},
      {"a compound store whose coordinate has side effects", "int k = i; m_ids[LiteMath::int2(k++, 0)] += 1u;",
       "compound assignment to a texel whose coordinate has side effects", "compute the coordinate into a variable first"},
      {"a sampler that is not a member", "LiteImage::Sampler local; out[i] = m_image.sample(local, LiteMath::float2(0.5f)).x;",
       "the sampler of m_image.sample() is not a member of the class", "declare the LiteImage::Sampler as a member"},
      {"an image passed as a value", "out[i] = Red(m_image, i);", "Image2D member 'm_image' used as a value in a kernel",
       "use its texels where the image is a member"},
      {"an image resized in a kernel", "m_image.resize(2, 2);", "Image2D::resize is not supported in kernels",
       "kernels read texels"},
      {"a texel type images cannot hold", "out[i] = m_uv[LiteMath::int2(i, 0)].x;", "Image2D member 'm_uv' has a texel type GPU images cannot hold",
       "use Image2D<float4>, Image2D<float> or Image2D<uint32_t>"},
      // Arrays of textures (std::vector<LiteImage::Texture2D<T>>).
      {"a texture of an array kept in a local", "const auto& t = m_textures[i]; out[i] = t.sample(LiteMath::float2(0.5f)).x;",
       "array of textures 'm_textures' used as a value in a kernel", "call its textures where the array is a member: m_textures[i].sample(uv)"},
      {"an array of textures changed in a kernel", "m_textures.pop_back();", "std::vector::pop_back of an array of textures in a kernel",
       "kernels read its size() and use its textures"},
      {"a texture's image reached in a kernel", "out[i] = m_textures[i].image()[LiteMath::int2(0, 0)].x;", "Texture2D::image is not supported in kernels",
       "kernels sample textures of an array (m_textures[i].sample(uv))"},
      {"an array of textures of uint texels", "out[i] = float(m_idTextures[i][LiteMath::int2(0, 0)]);",
       "array of textures 'm_idTextures' has a texel type GPU samplers cannot filter ('unsigned int')", "use LiteImage::Texture2D<float4> or Texture2D<float>"},
  };
  for (const Case& c : cases)
  {
    SECTION(c.name)
    {
      TempClass tc("Images", R"(#pragma once
#include "Image2D.h"
#include <cstdint>
#include <vector>
inline float Red(const LiteImage::Image2D<LiteMath::float4>& image, int i) { return image[LiteMath::int2(i, 0)].x; }
class Images
{
public:
  virtual ~Images() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out);
  LiteImage::Image2D<LiteMath::float4> m_image;
  LiteImage::Image2D<uint32_t> m_ids;
  LiteImage::Image2D<LiteMath::float2> m_uv;
  LiteImage::Sampler m_sampler;
  std::vector<LiteImage::Texture2D<LiteMath::float4>> m_textures;
  std::vector<LiteImage::Texture2D<uint32_t>> m_idTextures;
protected:
  void kernel1D_Run(int n, float* out);
};
)",
                   std::string(R"(#include "Images.h"
void Images::Run(int n, float* out) { kernel1D_Run(n, out); }
void Images::kernel1D_Run(int n, float* out)
{
  for (int i = 0; i < n; i++)
  {
    )") + c.body + "\n  }\n}\n");
      CommandResult r = RunCrossrt("translate --class Images --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                                   tc.Source("Images") + " --templates " CROSSRT_SOURCE_DIR "/templates -- -I" CROSSRT_SOURCE_DIR
                                   "/libs/litemath -I" CROSSRT_SOURCE_DIR "/libs/liteimage");
      INFO(r.output);
      REQUIRE_FALSE(r.crashed);
      REQUIRE(r.exitCode == 1);
      REQUIRE(std::regex_search(r.output, std::regex(R"(Images\.cpp:\d+:\d+: error: )")));
      REQUIRE(r.output.find(std::string("error: ") + c.message) != std::string::npos);
      REQUIRE(r.output.find(c.hint) != std::string::npos);
      REQUIRE(!std::filesystem::exists(tc.dir / "out" / "Images_Vulkan.cpp"));
    }
  }
}

TEST_CASE("Image2D parameters the GPU cannot bind are reported", "[diagnostics][images]")
{
  // Each case: Framer's declarations (after `protected:`) and its definitions; the error is in Framer.cpp.
  struct Case { const char* name; const char* declarations; const char* definitions; const char* message; const char* hint; };
  const Case cases[] = {
      {"a kernel taking an image by value", "  void kernel1D_Copy(Image img, int n, float* out);",
       "void Framer::Run(const Image& img, int n, float* out) { kernel1D_Copy(img, n, out); }\n"
       "void Framer::kernel1D_Copy(Image img, int n, float* out) { for (int i = 0; i < n; i++) out[i] = img[LiteMath::int2(i, 0)].x; }\n",
       "kernel parameter 'img' takes an Image2D by value", "take it by reference: 'const Image2D<T>& img' to read it"},
      {"a local image given to a kernel", "  void kernel1D_Copy(const Image& img, int n, float* out);",
       "void Framer::Run(const Image& img, int n, float* out) { Image copy = img; kernel1D_Copy(copy, n, out); }\n"
       "void Framer::kernel1D_Copy(const Image& img, int n, float* out) { for (int i = 0; i < n; i++) out[i] = img[LiteMath::int2(i, 0)].x; }\n",
       "Image2D argument of a kernel call must be an Image2D parameter of 'Run' or an Image2D member",
       "an image local to 'Run' has no GPU copy: make it a member"},
      {"an image given to a helper", "  void kernel1D_Copy(const Image& img, int n, float* out);",
       "static float Red(const Framer::Image& image, int i) { return image[LiteMath::int2(i, 0)].x; }\n"
       "void Framer::Run(const Image& img, int n, float* out) { kernel1D_Copy(img, n, out); }\n"
       "void Framer::kernel1D_Copy(const Image& img, int n, float* out) { for (int i = 0; i < n; i++) out[i] = Red(img, i); }\n",
       "helper 'Red' takes an Image2D parameter; on the GPU only kernels take images", "read the texels in the kernel and pass them to the helper"},
      {"an image parameter kept in a local", "  void kernel1D_Copy(const Image& img, int n, float* out);",
       "void Framer::Run(const Image& img, int n, float* out) { kernel1D_Copy(img, n, out); }\n"
       "void Framer::kernel1D_Copy(const Image& img, int n, float* out) { for (int i = 0; i < n; i++) { const Image& alias = img; out[i] = alias[LiteMath::int2(i, 0)].x; } }\n",
       "Image2D parameter 'img' used as a value in a kernel", "use its texels in the kernel itself: img[p]"},
      {"a part of a texel written", "  void kernel1D_Mark(Image& img, int n);",
       "void Framer::Run(const Image& img, int n, float* out) { (void)img; (void)out; kernel1D_Mark(m_frame, n); }\n"
       "void Framer::kernel1D_Mark(Image& img, int n) { for (int i = 0; i < n; i++) img[LiteMath::int2(i, 0)].x = 1.0f; }\n",
       "kernel writes part of a texel of Image2D parameter 'img'", "GPU images store whole texels"},
      {"an image parameter resized on the host", "  virtual void Resize(Image& img, int n);\n  void kernel1D_Mark(Image& img, int n);",
       "void Framer::Run(const Image& img, int n, float* out) { (void)img; (void)out; kernel1D_Mark(m_frame, n); }\n"
       "void Framer::Resize(Image& img, int n) { img.resize(uint32_t(n), 1); kernel1D_Mark(img, n); }\n"
       "void Framer::kernel1D_Mark(Image& img, int n) { for (int i = 0; i < n; i++) img[LiteMath::int2(i, 0)] = LiteMath::float4(1.0f); }\n",
       "control function 'Resize' changes Image2D parameter 'img' on the host ('resize')",
       "its GPU copy is made before the body runs: size and fill the image before calling 'Resize'"},
      {"an image parameter of a texel type images cannot hold", "  void kernel1D_Uv(const LiteImage::Image2D<LiteMath::float2>& uv, int n, float* out);",
       "void Framer::Run(const Image& img, int n, float* out) { (void)img; kernel1D_Uv(LiteImage::Image2D<LiteMath::float2>(), n, out); }\n"
       "void Framer::kernel1D_Uv(const LiteImage::Image2D<LiteMath::float2>& uv, int n, float* out) { for (int i = 0; i < n; i++) out[i] = uv[LiteMath::int2(i, 0)].x; }\n",
       "kernel parameter 'uv' is an Image2D of 'LiteMath::float2', which GPU images cannot hold", "use Image2D<float4>, Image2D<float> or Image2D<uint32_t>"},
      {"an image given to a kernel of a thread loop of several kernels", "  void kernel_Load(uint32_t tid, const Image& img, float* v);\n  void kernel_Store(uint32_t tid, const float* v, float* out);",
       "void Framer::Run(const Image& img, int n, float* out) { for (int i = 0; i < n; i++) { float v; kernel_Load(i, img, &v); kernel_Store(i, &v, out); } }\n"
       "void Framer::kernel_Load(uint32_t tid, const Image& img, float* v) { *v = img[LiteMath::int2(int(tid), 0)].x; }\n"
       "void Framer::kernel_Store(uint32_t tid, const float* v, float* out) { out[tid] = *v; }\n",
       "Image2D argument of 'kernel_Load' in a thread loop that calls several kernels", "make the image a member of the class, or give the kernel a thread loop of its own"},
  };
  for (const Case& c : cases)
  {
    SECTION(c.name)
    {
      TempClass tc("Framer", std::string(R"(#pragma once
#include "Image2D.h"
#include <cstdint>
class Framer
{
public:
  using Image = LiteImage::Image2D<LiteMath::float4>;
  virtual ~Framer() = default;
  virtual void Run(const Image& img, int n, [[crossrt::size("n")]] float* out);
  Image m_frame;
protected:
)") + c.declarations + "\n};\n",
                   std::string("#include \"Framer.h\"\n") + c.definitions);
      CommandResult r = RunCrossrt("translate --class Framer --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                                   tc.Source("Framer") + " --templates " CROSSRT_SOURCE_DIR "/templates -- -I" CROSSRT_SOURCE_DIR
                                   "/libs/litemath -I" CROSSRT_SOURCE_DIR "/libs/liteimage");
      INFO(r.output);
      REQUIRE_FALSE(r.crashed);
      REQUIRE(r.exitCode == 1);
      REQUIRE(std::regex_search(r.output, std::regex(R"(Framer\.(cpp|h):\d+:\d+: error: )")));
      REQUIRE(r.output.find(std::string("error: ") + c.message) != std::string::npos);
      REQUIRE(r.output.find(c.hint) != std::string::npos);
      REQUIRE(!std::filesystem::exists(tc.dir / "out" / "Framer_Vulkan.cpp"));
    }
  }
}

TEST_CASE("Thread loops of several kernels that the GPU cannot run per thread are reported", "[diagnostics][modes]")
{
  // Each case: Looper's extra declarations, Run's body from Looper.cpp's line 4 on (the thread loop
  // starts there), and extra definitions.
  struct Case { const char* name; const char* declarations; const char* body; const char* definitions; int line; const char* message; const char* hint; };
  const Case cases[] = {
      {"a branch in the loop body", "", "    float v;\n    kernel_Init(i, &v);\n    if (n > 2) kernel_Step(i, &v);\n    kernel_Store(i, &v, out);\n", "", 7,
       "the thread loop of 'Run' may branch only on a kernel's bool result, to leave a loop inside it", "branch on anything else inside the kernels"},
      {"other code in the loop body", "", "    float v;\n    kernel_Init(i, &v);\n    n = n + 1;\n    kernel_Store(i, &v, out);\n", "", 7,
       "the thread loop of 'Run' may hold only per-thread local declarations, kernel_ calls and counted loops around them", "move this code into a kernel"},
      {"a loop bound that differs per thread", "", "    float v;\n    kernel_Init(i, &v);\n    for (int s = 0; s < i; s++) kernel_Step(i, &v);\n    kernel_Store(i, &v, out);\n", "", 7,
       "'i' differs from thread to thread, but the loop's condition in the thread loop of 'Run' runs once for all threads in wavefront mode",
       "branch inside the kernels"},
      {"a per-thread value passed by value", "  void kernel_Scale(uint32_t tid, float factor, float* value);",
       "    float v;\n    kernel_Init(i, &v);\n    kernel_Scale(i, v, &v);\n    kernel_Store(i, &v, out);\n",
       "void Looper::kernel_Scale(uint32_t tid, float factor, float* value) { (void)tid; *value *= factor; }\n", 7,
       "'v' differs from thread to thread, but the by-value argument 'factor' in the thread loop of 'Run' runs once for all threads in wavefront mode",
       "pass per-thread values to kernels by address (&v)"},
      {"a per-thread value indexed as an array", "  void kernel_Spread(uint32_t tid, float* value);",
       "    float v;\n    kernel_Init(i, &v);\n    kernel_Step(i, &v);\n    kernel_Spread(i, &v);\n    kernel_Store(i, &v, out);\n",
       "void Looper::kernel_Spread(uint32_t tid, float* value) { (void)tid; value[1] = 0.0f; }\n", 15,
       "'value' holds one value per thread (a local of the control function's thread loop), used here as a pointer", "read and write it as *value"},
      {"a per-thread parameter given a buffer elsewhere", "  virtual void Other(int n, [[crossrt::size(\"n\")]] float* out);",
       "    float v;\n    kernel_Init(i, &v);\n    kernel_Step(i, &v);\n    kernel_Store(i, &v, out);\n",
       "void Looper::Other(int n, float* out) { for (int i = 0; i < n; i++) kernel_Step(i, out); }\n", 14,
       "parameter 'value' of 'kernel_Step' gets a local's address in a thread loop, so on the GPU it holds one value per thread, but here it is given a buffer",
       "give the kernel a separate buffer parameter"},
      {"thread ids that do not match the loops", "  void kernel_Row(uint32_t tidY, float* value);",
       "    float v;\n    kernel_Row(i, &v);\n    kernel_Row(i, &v);\n",
       "void Looper::kernel_Row(uint32_t tidY, float* value) { *value = float(tidY); }\n", 4,
       "the loops of a thread loop of 'Run' do not match the thread ids of its kernels", "with one loop pass it as tid (or tidX)"},
      {"a local of a type the GPU has no equivalent of", "",
       "    double d;\n    float v;\n    kernel_Init(i, &v);\n    kernel_Store(i, &v, out);\n", "", 5,
       "per-thread local 'd' of type 'double' has no GPU equivalent", "use int, uint, float, LiteMath types"},
  };
  for (const Case& c : cases)
  {
    SECTION(c.name)
    {
      TempClass tc("Looper", std::string(R"(#pragma once
#include <cstdint>
#include <vector>
class Looper
{
public:
  virtual ~Looper() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out);
protected:
  void kernel_Init(uint32_t tid, float* value);
  void kernel_Step(uint32_t tid, float* value);
  void kernel_Store(uint32_t tid, const float* value, float* out);
)") + c.declarations + "\n};\n",
                   std::string("#include \"Looper.h\"\nvoid Looper::Run(int n, float* out)\n{\n  for (int i = 0; i < n; i++) {\n") + c.body + "  }\n}\n" +
                       "void Looper::kernel_Init(uint32_t tid, float* value) { *value = float(tid); }\n"
                       "void Looper::kernel_Step(uint32_t tid, float* value) { (void)tid; *value = *value * 0.5f + 1.0f; }\n"
                       "void Looper::kernel_Store(uint32_t tid, const float* value, float* out) { out[tid] = *value; }\n" +
                       c.definitions);
      CommandResult r = RunCrossrt("translate --class Looper --backend vulkan --out " + (tc.dir / "out").string() + " --source " +
                                   tc.Source("Looper") + " --templates " CROSSRT_SOURCE_DIR "/templates");
      INFO(r.output);
      REQUIRE_FALSE(r.crashed);
      REQUIRE(r.exitCode == 1);
      REQUIRE(r.output.find("Looper.cpp:" + std::to_string(c.line) + ":") != std::string::npos);
      REQUIRE(r.output.find(std::string("error: ") + c.message) != std::string::npos);
      REQUIRE(r.output.find(c.hint) != std::string::npos);
      REQUIRE(!std::filesystem::exists(tc.dir / "out" / "Looper_Vulkan.cpp"));
    }
  }
}

TEST_CASE("A class in a namespace is found by its qualified name, and only by it", "[diagnostics][namespace]")
{
  TempClass tc("Scaler", R"(#pragma once
namespace demo
{
class Scaler
{
public:
  virtual ~Scaler() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* data);
protected:
  void kernel1D_Scale(int n, float* data);
};
}  // namespace demo
)",
               R"(#include "Scaler.h"
namespace demo
{
void Scaler::Run(int n, float* data) { kernel1D_Scale(n, data); }
void Scaler::kernel1D_Scale(int n, float* data)
{
  for (int i = 0; i < n; i++) data[i] *= 2.0f;
}
}  // namespace demo
)");
  auto translate = [&](const std::string& name) {
    return RunCrossrt("translate --class " + name + " --backend cpu --out " + (tc.dir / "out").string() + " --source " +
                      tc.Source("Scaler") + " --templates " CROSSRT_SOURCE_DIR "/templates");
  };
  for (const char* wrong : {"Scaler", "other::Scaler", "demo::", "demo::Scaler::Run"})
  {
    INFO(wrong);
    CommandResult r = translate(wrong);
    INFO(r.output);
    REQUIRE_FALSE(r.crashed);
    REQUIRE(r.exitCode == 1);
    REQUIRE(r.output.find(std::string("error: class '") + wrong + "' is not defined in") != std::string::npos);
    REQUIRE(r.output.find("hint: check the name given to crossrt_add_class; name a class in a namespace with it") != std::string::npos);
    REQUIRE(!std::filesystem::exists(tc.dir / "out" / "Scaler_CPU.h"));
  }
  CommandResult r = translate("demo::Scaler");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  std::ifstream header(tc.dir / "out" / "Scaler_CPU.h");
  const std::string text((std::istreambuf_iterator<char>(header)), std::istreambuf_iterator<char>());
  REQUIRE(text.find("namespace demo\n{\nclass Scaler_CPU : public Scaler") != std::string::npos);
}

TEST_CASE("kernel_slicer's setter form: writes through a member's pointers run on the CPU, and are a clear error on the GPU and ISPC",
          "[diagnostics]")
{
  // The output pointers live in a member struct (kernel_slicer's [[kslicer::setter]] SetOutput). Each
  // thread writes its own element: no data race, and the CPU class runs the kernel as written.
  auto header = [](const std::string& name) {
    return "#pragma once\nstruct Outputs { float* sums; float* products; };\nclass " + name + R"(
{
public:
  virtual ~)" + name + R"(() = default;
  void SetOutput(Outputs out) { m_out = out; }
  virtual void Process(int n, [[crossrt::size("n")]] const float* a, [[crossrt::size("n")]] const float* b);
protected:
  void kernel1D_Process(int n, const float* a, const float* b);
  Outputs m_out;
};
)";
  };
  auto source = [](const std::string& name, const std::string& write) {
    return "#include \"" + name + ".h\"\nvoid " + name + "::Process(int n, const float* a, const float* b) { kernel1D_Process(n, a, b); }\nvoid " + name +
           "::kernel1D_Process(int n, const float* a, const float* b)\n{\n  for (int i = 0; i < n; i++)\n  {\n    m_out.sums[i] = a[i] + b[i];\n    " + write +
           "\n  }\n}\n";
  };
  auto translate = [](const TempClass& tc, const std::string& name, const std::string& backend) {
    return RunCrossrt("translate --class " + name + " --backend " + backend + " --out " + (tc.dir / ("out_" + backend)).string() + " --source " +
                      tc.Source(name) + " --templates " CROSSRT_SOURCE_DIR "/templates");
  };
  SECTION("each thread at its index")
  {
    TempClass tc("Setter", header("Setter"), source("Setter", "m_out.products[i] = a[i] * b[i];"));
    CommandResult cpu = translate(tc, "Setter", "cpu");
    INFO(cpu.output);
    REQUIRE(cpu.exitCode == 0);
    for (const char* backend : {"vulkan", "ispc"})
    {
      CommandResult r = translate(tc, "Setter", backend);
      INFO(backend << ": " << r.output);
      REQUIRE_FALSE(r.crashed);
      REQUIRE(r.exitCode == 1);
      REQUIRE(r.output.find("Setter.cpp:7:") != std::string::npos);
      REQUIRE(r.output.find("kernel writes through pointer member 'm_out' (kernel_slicer's setter form)") != std::string::npos);
      REQUIRE(r.output.find("the CPU backend runs this kernel as written") != std::string::npos);
    }
  }
  SECTION("one element from every thread stays a data race on the CPU too")
  {
    TempClass tc("SetterRace", header("SetterRace"), source("SetterRace", "m_out.products[0] = a[i];"));
    CommandResult cpu = translate(tc, "SetterRace", "cpu");
    INFO(cpu.output);
    REQUIRE(cpu.exitCode == 1);
    REQUIRE(cpu.output.find("SetterRace.cpp:8:") != std::string::npos);
    REQUIRE(cpu.output.find("kernel writes one element through pointer member 'm_out' from every thread (a data race)") != std::string::npos);
  }
  SECTION("a helper member function writing at the index it is given (kernel_slicer's test 005)")
  {
    auto withHelper = [&](const std::string& name, const std::string& index) {
      std::string h = header(name);
      h.insert(h.find("  Outputs m_out;"), "  void SetProduct(int i, float v) { m_out.products[" + index + "] = v; }\n");
      return TempClass(name, h, source(name, "SetProduct(i, a[i] * b[i]);"));
    };
    TempClass tc = withHelper("SetterHelper", "i");
    CommandResult cpu = translate(tc, "SetterHelper", "cpu");
    INFO(cpu.output);
    REQUIRE(cpu.exitCode == 0);
    CommandResult gpu = translate(tc, "SetterHelper", "vulkan");
    REQUIRE(gpu.exitCode == 1);
    REQUIRE(gpu.output.find("helper function 'SetProduct' writes through pointer member 'm_out' (kernel_slicer's setter form)") != std::string::npos);
    TempClass race = withHelper("SetterHelperRace", "0");
    CommandResult raced = translate(race, "SetterHelperRace", "cpu");
    INFO(raced.output);
    REQUIRE(raced.exitCode == 1);
    REQUIRE(raced.output.find("helper function 'SetProduct' writes one element through pointer member 'm_out' from every thread (a data race)") !=
            std::string::npos);
  }
}

TEST_CASE("Elements of a member array reduced in a kernel: every backend, and on the GPU a clear error past 256 bytes", "[diagnostics]")
{
  // float m_sums[2] (8 bytes) translates everywhere; float m_bins[100] (400 bytes, a copy in every GPU
  // thread) is refused on the GPU at its reduction, and taken by the CPU and ISPC backends.
  for (const char* size : {"2", "100"})
  {
    const std::string name = std::string("ArrayReduce") + size;
    TempClass tc(name, "#pragma once\nclass " + name + "\n{\npublic:\n  virtual ~" + name + "() = default;\n"
                 "  virtual void Sum(int n, [[crossrt::size(\"n\")]] const float* a);\n  float m_sums[" + size + "];\nprotected:\n"
                 "  void kernel1D_Sum(int n, const float* a);\n};\n",
                 "#include \"" + name + ".h\"\nvoid " + name + "::Sum(int n, const float* a) { kernel1D_Sum(n, a); }\n"
                 "void " + name + "::kernel1D_Sum(int n, const float* a)\n{\n  for (int i = 0; i < n; i++)\n  {\n    m_sums[0] += a[i];\n"
                 "    m_sums[i % " + size + "] += 2.0f * a[i];\n  }\n}\n");
    for (const char* backend : {"cpu", "vulkan", "ispc"})
    {
      CommandResult r = RunCrossrt("translate --class " + name + " --backend " + std::string(backend) + " --out " + (tc.dir / backend).string() +
                                   " --source " + tc.Source(name) + " --templates " CROSSRT_SOURCE_DIR "/templates");
      INFO(name << ", " << backend << ": " << r.output);
      REQUIRE_FALSE(r.crashed);
      if (std::string(size) == "2" || std::string(backend) != "vulkan")
      {
        REQUIRE(r.exitCode == 0);
        continue;
      }
      REQUIRE(r.exitCode == 1);
      REQUIRE(r.output.find(name + ".cpp:7:") != std::string::npos);
      REQUIRE(r.output.find("kernel 'kernel1D_Sum' reduces the 100 elements of member array 'm_sums' (400 bytes; a GPU thread holds at most 256)") !=
              std::string::npos);
      REQUIRE(r.output.find("InterlockedAdd") != std::string::npos);
    }
  }
  // A local array declared before the loop, reduced element by element: the same limit on the GPU.
  TempClass local("LocalBins100", "#pragma once\nclass LocalBins100\n{\npublic:\n  virtual ~LocalBins100() = default;\n"
                  "  virtual void Sum(int n, [[crossrt::size(\"n\")]] const float* a, [[crossrt::size(\"1\")]] float* a_out);\nprotected:\n"
                  "  void kernel1D_Sum(int n, const float* a, float* a_out);\n};\n",
                  "#include \"LocalBins100.h\"\nvoid LocalBins100::Sum(int n, const float* a, float* a_out) { kernel1D_Sum(n, a, a_out); }\n"
                  "void LocalBins100::kernel1D_Sum(int n, const float* a, float* a_out)\n{\n  float bins[100] = {};\n"
                  "  for (int i = 0; i < n; i++)\n    bins[i % 100] += a[i];\n  a_out[0] = bins[7];\n}\n");
  for (const char* backend : {"cpu", "vulkan", "ispc"})
  {
    CommandResult r = RunCrossrt("translate --class LocalBins100 --backend " + std::string(backend) + " --out " + (local.dir / backend).string() +
                                 " --source " + local.Source("LocalBins100") + " --templates " CROSSRT_SOURCE_DIR "/templates");
    INFO(backend << ": " << r.output);
    REQUIRE_FALSE(r.crashed);
    REQUIRE(r.exitCode == (std::string(backend) == "vulkan" ? 1 : 0));
    if (r.exitCode == 1)
      REQUIRE(r.output.find("LocalBins100.cpp:5:9: error: kernel 'kernel1D_Sum' reduces the 100 elements of local array 'bins' (400 bytes") !=
              std::string::npos);
  }
}
