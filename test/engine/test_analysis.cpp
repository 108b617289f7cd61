// What the analysis finds in small input classes parsed with the real standard library.
#include "parse/AstCache.h"
#include "EngineSupport.h"
#include <algorithm>

using namespace crossrt::engine;

namespace {

const char* kHeader = R"(#pragma once
#include "LiteMath.h"
#include <vector>
#include <string>
#include <map>
using namespace LiteMath;
struct Item { float4 a; float b; };
class Finder
{
public:
  virtual ~Finder() = default;
  virtual void Run(int n, [[crossrt::size("n * 2")]] const float* in, float* out __attribute__((size("n"))));
  virtual void RunRtv(int w, int h, [[crossrt::size("w*h")]] float* img);
  void NotAControl(int n);
  virtual void CommitDeviceData() {}
protected:
  void kernel1D_Scale(int n, const float* in, float* out);
  void kernel2D_Fill(int w, int h, float* img);
  void kernel_Pixel(int tidX, int tidY, int w, float* img);
  float m_scale = 2.0f;
  float m_total = 0.0f;
  float3 m_lo;
  std::vector<Item> m_items;
  std::vector<float3> m_points;
  std::string m_name;                 // never used by kernels: ignored
  std::map<int, int> m_lookup;        // ditto
};
)";

const char* kSource = R"(#include "Finder.h"
void Finder::Run(int n, const float* in, float* out)
{
  m_total = 0.0f;
  kernel1D_Scale(n, in, out);
}
void Finder::RunRtv(int w, int h, float* img)
{
  kernel2D_Fill(w, h, img);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      kernel_Pixel(x, y, w, img);
}
void Finder::NotAControl(int n) { m_scale = float(n); }
void Finder::kernel1D_Scale(int n, const float* in, float* out)
{
  for (int i = 0; i < n; i++)
  {
    out[i] = in[2 * i] * m_scale + m_items[i % m_items.size()].b;
    m_total += out[i];
    m_lo = min(m_lo, m_points[i]);
  }
}
void Finder::kernel2D_Fill(int w, int h, float* img)
{
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      img[y * w + x] = float(x + y);
}
void Finder::kernel_Pixel(int tidX, int tidY, int w, float* img) { img[tidY * w + tidX] *= 0.5f; }
)";

const Kernel* FindKernel(const ClassModel& m, const std::string& name)
{
  for (auto& k : m.kernels)
    if (k.name == name) return &k;
  return nullptr;
}

}  // namespace

TEST_CASE("Analysis finds kernels, control functions, members and reductions", "[engine]")
{
  TempClass tc("Finder", kHeader, kSource);
  AnalyzeResult r = Analyze(MakeRequest(tc, "Finder"));
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  const ClassModel& m = r.model;

  REQUIRE(m.kernels.size() == 3);
  const Kernel* scale = FindKernel(m, "kernel1D_Scale");
  REQUIRE(scale);
  CHECK_FALSE(scale->rtv);
  CHECK(scale->dims == 1);
  REQUIRE(scale->loops.size() == 1);
  CHECK(scale->loops[0].var == "i");
  CHECK(scale->loops[0].countCpp == "n");
  REQUIRE(scale->reductions.size() == 2);
  CHECK(scale->reductions[0].member == "m_total");  // in declaration order
  CHECK(scale->reductions[0].op == ReduceOp::Add);
  CHECK(scale->reductions[1].member == "m_lo");
  CHECK(scale->reductions[1].op == ReduceOp::Min);
  CHECK(scale->memberVectors == std::vector<std::string>{"m_items", "m_points"});

  const Kernel* fill = FindKernel(m, "kernel2D_Fill");
  REQUIRE(fill);
  CHECK(fill->dims == 2);
  CHECK(fill->loops[0].var == "y");  // outermost first
  CHECK(fill->loops[1].var == "x");

  const Kernel* pixel = FindKernel(m, "kernel_Pixel");
  REQUIRE(pixel);
  CHECK(pixel->rtv);
  CHECK(pixel->dims == 2);

  // Control functions: only those calling kernels, with their size annotations.
  REQUIRE(m.controls.size() == 2);
  const Control& run = m.controls[0].name == "Run" ? m.controls[0] : m.controls[1];
  const Control& rtv = m.controls[0].name == "Run" ? m.controls[1] : m.controls[0];
  REQUIRE(run.params.size() == 3);
  CHECK(run.params[1].sizeExpr == "n * 2");
  CHECK(run.params[1].isConst);
  CHECK(run.params[2].sizeExpr == "n");
  CHECK_FALSE(run.params[2].isConst);
  CHECK(run.vulkanCmdBody.find("kernel1D_ScaleCmd(crt_cmd, n, crt_inOut_Run.in, crt_inOut_Run.out)") != std::string::npos);
  CHECK(rtv.vulkanCmdBody.find("kernel_PixelCmd(crt_cmd, w, h, w, crt_inOut_RunRtv.img);") != std::string::npos);
  CHECK(rtv.cpuBody.find("crossrt::ParallelFor<") != std::string::npos);
  CHECK(rtv.cpuBody.find("crt_first") != std::string::npos);

  // Members: plain data and vectors; the vector of float3 needs the scalar layout to match C++.
  bool sawItems = false, sawPoints = false, sawName = false;
  for (auto& mem : m.members)
  {
    if (mem.name == "m_items") { sawItems = true; CHECK(mem.kind == MemberKind::Vector); CHECK_FALSE(mem.scalarLayout); }
    if (mem.name == "m_points") { sawPoints = true; CHECK(mem.scalarLayout); }
    if (mem.name == "m_name") sawName = true;
  }
  CHECK(sawItems);
  CHECK(sawPoints);
  CHECK_FALSE(sawName);
  CHECK(m.declaresCommitDeviceData);
  CHECK_FALSE(m.declaresGetExecutionTime);
}

TEST_CASE("Generated GLSL keeps the user's names and compiles", "[engine]")
{
  TempClass tc("Finder", kHeader, kSource);
  TranslateResult r = Translate(MakeRequest(tc, "Finder"));
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  const std::string glsl = Squeezed(r.files.at("shaders/kernel1D_Scale.comp"));
  CHECK(glsl.find(Squeezed("void kernel1D_Scale(int i)")) != std::string::npos);
  CHECK(glsl.find(Squeezed("out_[i] = in_[2 * i] * m_scale")) != std::string::npos);  // 'in'/'out' are GLSL keywords
  CHECK(glsl.find(Squeezed("layout(scalar, binding")) != std::string::npos);          // m_points: float3 array
  CHECK(r.files.count("Finder_Vulkan.h") == 1);
  CHECK(r.files.count("Finder_Vulkan_shaders.cpp") == 1);
  // A translation is deterministic: the same input gives the same bytes.
  TranslateResult again = Translate(MakeRequest(tc, "Finder"));
  CHECK(again.files == r.files);
}

TEST_CASE("std::numeric_limits in kernels and their constants becomes GLSL constant expressions", "[engine]")
{
  const char* header = R"(#pragma once
#include "LiteMath.h"
#include <limits>
constexpr float kFar = std::numeric_limits<float>::infinity();
class Limits
{
public:
  virtual ~Limits() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out, [[crossrt::size("n")]] int* ints);
  virtual void CommitDeviceData() {}
protected:
  void kernel1D_Fill(int n, float* out, int* ints);
};
)";
  const char* source = R"(#include "Limits.h"
void Limits::Run(int n, float* out, int* ints) { kernel1D_Fill(n, out, ints); }
void Limits::kernel1D_Fill(int n, float* out, int* ints)
{
  for (int i = 0; i < n; i++)
  {
    out[i] = i == 0 ? kFar : i == 1 ? std::numeric_limits<float>::max() : std::numeric_limits<float>::epsilon();
    ints[i] = i == 0 ? std::numeric_limits<int>::lowest() : std::numeric_limits<int>::max();
  }
}
)";
  TempClass tc("Limits", header, source);
  TranslateResult r = Translate(MakeRequest(tc, "Limits"));
  INFO(r.diagnostics);
  REQUIRE(r.ok);  // the GLSL compiled: a global constant needs a constant expression
  const std::string glsl = Squeezed(r.files.at("shaders/kernel1D_Fill.comp"));
  INFO(glsl);
  CHECK(glsl.find(Squeezed("const float kFar = (1.0 / 0.0);")) != std::string::npos);
  CHECK(glsl.find(Squeezed("3.40282347e+38")) != std::string::npos);
  CHECK(glsl.find(Squeezed("1.1920929e-07")) != std::string::npos);
  CHECK(glsl.find(Squeezed("(-2147483647 - 1)")) != std::string::npos);
  CHECK(glsl.find(Squeezed("0x7FFFFFFF")) != std::string::npos);
}

TEST_CASE("The CPU backend parallelises kernels on all cores, each chunk with parts of the reductions", "[engine]")
{
  TempClass tc("Finder", kHeader, kSource);
  TranslateResult r = Translate(MakeRequest(tc, "Finder", Backend::Cpu));
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  const std::string cpp = Squeezed(r.files.at("Finder_CPU.cpp"));
  // Chunks of the outer loop on the pool's threads and this one (crossrt::ParallelFor).
  CHECK(cpp.find(Squeezed("crossrt::ParallelFor<int>(crt_loop.parallel, 0, n, 1024, [&](int crt_first, int crt_last) {")) != std::string::npos);
  CHECK(cpp.find(Squeezed("for (int i = crt_first; i < crt_last; i++)")) != std::string::npos);
  CHECK(cpp.find("#pragma omp") == std::string::npos);
  // Each chunk reduces into its own part, merged into the total after its iterations.
  CHECK(cpp.find(Squeezed("crt_reductions.StartFromZero(crt_m_totalLocal);")) != std::string::npos);
  CHECK(cpp.find(Squeezed("crt_m_totalLocal += out[i];")) != std::string::npos);
  CHECK(cpp.find(Squeezed("crt_reductions.Merge(crt_m_totalTotal, crt_m_totalLocal, crossrt::Sum());")) != std::string::npos);
  CHECK(cpp.find(Squeezed("crt_reductions.StartFromTotal(crt_m_loLocal, crt_m_loTotal);")) != std::string::npos);
  CHECK(cpp.find(Squeezed("crt_reductions.Merge(crt_m_loTotal, crt_m_loLocal, crossrt::Minimum());")) != std::string::npos);
  // On all cores, or on this thread while that has been faster here (crossrt::ParallelChoice).
  CHECK(cpp.find(Squeezed("static crossrt::ParallelChoice crt_choice;")) != std::string::npos);
  CHECK(cpp.find(Squeezed("crt_choice.End(crt_loop);")) != std::string::npos);
}

TEST_CASE("Target compile options: meaning-changing flags are kept, GCC-only ones dropped", "[engine]")
{
  TranslateRequest r;
  r.compileArgs = {"-I/a", "-isystem", "/b", "-DX=1", "-O3", "-Wall", "-Wno-attributes=crossrt::size",
                   "-fconcepts-diagnostics-depth=2", "-march=x86-64", "-fopenmp", "-std=c++20", "-include", "pre.h"};
  auto args = ParseArguments(r);
  auto has = [&](const std::string& a) { return std::find(args.begin(), args.end(), a) != args.end(); };
  CHECK(has("-I/a"));
  CHECK(has("-isystem"));
  CHECK(has("/b"));
  CHECK(has("-DX=1"));
  CHECK(has("-march=x86-64"));
  CHECK(has("-fopenmp"));
  CHECK(has("-std=c++20"));
  CHECK(std::count_if(args.begin(), args.end(), [](const std::string& a) { return a.rfind("-std=", 0) == 0; }) == 1);
  r.compileArgs = {"-std=c++17", "cxx_std_20", "cxx_std_11"};  // CMake compile features count too
  auto withFeatures = ParseArguments(r);
  CHECK(std::find(withFeatures.begin(), withFeatures.end(), "-std=c++20") != withFeatures.end());
  CHECK(std::find(withFeatures.begin(), withFeatures.end(), "-std=c++17") == withFeatures.end());
  CHECK(has("pre.h"));
  CHECK_FALSE(has("-O3"));
  CHECK_FALSE(has("-Wall"));
  CHECK_FALSE(has("-Wno-attributes=crossrt::size"));
  CHECK_FALSE(has("-fconcepts-diagnostics-depth=2"));

  // With a GCC-only flag among the target's options, the class still parses, and -D applies.
  TempClass tc("Finder", std::string("#if SCALE != 3\n#error SCALE must come from the options\n#endif\n") + kHeader, kSource);
  auto req = MakeRequest(tc, "Finder");
  req.compileArgs.insert(req.compileArgs.end(), {"-DSCALE=3", "-fconcepts-diagnostics-depth=2", "-O2"});
  AnalyzeResult a = Analyze(req);
  INFO(a.diagnostics);
  CHECK(a.ok);
}

TEST_CASE("Ray queries through ISceneObject get a variant for ray tracing hardware without the composed traversal", "[engine][composition]")
{
  // The real example: PrimaryRays composing BVHScene (both from the source tree).
  TranslateRequest r;
  r.className = "PrimaryRays";
  r.sources = {CROSSRT_SOURCE_DIR "/examples/primary_rays/PrimaryRays.cpp", CROSSRT_SOURCE_DIR "/libs/litert/BVHScene.cpp"};
  r.compileArgs = {"-std=c++17", "-I" CROSSRT_SOURCE_DIR "/libs/litemath", "-I" CROSSRT_SOURCE_DIR "/libs/litert",
                   "-I" CROSSRT_SOURCE_DIR "/libs/litebvh", "-I" CROSSRT_SOURCE_DIR "/libs/litesdf",
                   "-I" CROSSRT_SOURCE_DIR "/examples/primary_rays"};
  r.templateDir = CROSSRT_SOURCE_DIR "/templates";
  r.outputDir = (fs::temp_directory_path() / "crossrt-test-rayquery").string();
  r.compositions = {"ISceneObject=BVHScene"};
  const TranslateResult result = Translate(r);
  INFO(result.diagnostics);
  REQUIRE(result.ok);
  const std::string software = Squeezed(result.files.at("shaders/kernel2D_Render.comp"));
  const std::string hardware = Squeezed(result.files.at("shaders/kernel2D_Render_RayQuery.comp"));
  // The software variant runs BVHScene's traversal over its buffers; the hardware one has none of it.
  CHECK(software.find(Squeezed("m_pAccelStruct_m_nodes[]")) != std::string::npos);
  CHECK(software.find(Squeezed("GL_EXT_ray_query")) == std::string::npos);
  CHECK(hardware.find(Squeezed("#extension GL_EXT_ray_query : require")) != std::string::npos);
  CHECK(hardware.find(Squeezed("uniform accelerationStructureEXT m_pAccelStruct_scene;")) != std::string::npos);
  CHECK(hardware.find(Squeezed("CRT_Hit m_pAccelStruct_RayQuery_NearestHit(vec4 posAndNear, vec4 dirAndFar)")) != std::string::npos);
  CHECK(hardware.find(Squeezed("bool m_pAccelStruct_RayQuery_AnyHit(vec4 posAndNear, vec4 dirAndFar)")) != std::string::npos);
  for (const char* gone : {"m_pAccelStruct_m_nodes[]", "m_pAccelStruct_m_triangles[]", "m_pAccelStruct_Trace(", "struct BVH4Node", "m_pAccelStruct_kLeafFlag"})
  {
    INFO(gone);
    CHECK(hardware.find(Squeezed(gone)) == std::string::npos);
  }
  // The class's own data and helpers stay: the kernel body is the same text in both.
  CHECK(hardware.find(Squeezed("m_vertices[]")) != std::string::npos);
  const auto body = [](const std::string& glsl) { return glsl.substr(glsl.find(Squeezed("void kernel2D_Render("))); };
  CHECK(body(hardware) == body(software));
  // The host binds the variant where the device has ray queries.
  const std::string host = Squeezed(result.files.at("PrimaryRays_Vulkan.cpp"));
  CHECK(host.find(Squeezed("crossrt::Binding::SceneOf(crt_scenes.m_pAccelStruct)")) != std::string::npos);
  CHECK(host.find(Squeezed("crt_useRayTracingHardware = crt_ctx->hasRayQuery;")) != std::string::npos);
}

TEST_CASE("A thread loop whose kernels trace through a composed ISceneObject gets a megakernel with the traversal merged in", "[engine][modes]")
{
  TempClass tc("Tracer", R"(#pragma once
#include "CrossRT.h"
#include <cstdint>
#include <memory>
using LiteMath::float4;
class Tracer
{
public:
  virtual ~Tracer() = default;
  virtual void Trace(uint32_t n, [[crossrt::size("2 * n")]] const float4* rays, [[crossrt::size("n")]] float* depth);
  std::shared_ptr<ISceneObject> m_pAccelStruct;
protected:
  void kernel_Hit(uint32_t tid, const float4* rays, CRT_Hit* hit);
  void kernel_Depth(uint32_t tid, const CRT_Hit* hit, float* depth);
};
)",
               R"(#include "Tracer.h"
void Tracer::Trace(uint32_t n, const float4* rays, float* depth)
{
  for (uint32_t i = 0; i < n; i++)
  {
    CRT_Hit hit;
    kernel_Hit(i, rays, &hit);
    kernel_Depth(i, &hit, depth);
  }
}
void Tracer::kernel_Hit(uint32_t tid, const float4* rays, CRT_Hit* hit) { *hit = m_pAccelStruct->RayQuery_NearestHit(rays[2 * tid], rays[2 * tid + 1]); }
void Tracer::kernel_Depth(uint32_t tid, const CRT_Hit* hit, float* depth) { depth[tid] = hit->primId == 0xFFFFFFFFu ? -1.0f : hit->t; }
)");
  TranslateRequest r = MakeRequest(tc, "Tracer");
  r.sources.push_back(CROSSRT_SOURCE_DIR "/libs/litert/BVHScene.cpp");
  r.compileArgs.insert(r.compileArgs.end(), {"-std=c++17", "-I" CROSSRT_SOURCE_DIR "/libs/litert", "-I" CROSSRT_SOURCE_DIR "/libs/litebvh",
                                              "-I" CROSSRT_SOURCE_DIR "/libs/litesdf"});
  r.compositions = {"ISceneObject=BVHScene"};
  const TranslateResult result = Translate(r);  // every shader is compiled by glslang on the way
  INFO(result.diagnostics);
  REQUIRE(result.ok);
  const std::string mega = Squeezed(result.files.at("shaders/Trace_Megakernel.comp"));
  // The megakernel holds the traversal, both kernels' thread functions, and the hit as a local.
  CHECK(mega.find(Squeezed("m_pAccelStruct_m_nodes[]")) != std::string::npos);
  CHECK(mega.find(Squeezed("CRT_Hit m_pAccelStruct_RayQuery_NearestHit(")) != std::string::npos);
  CHECK(mega.find(Squeezed("void kernel_Hit(uint tid, inout CRT_Hit hit)")) != std::string::npos);
  CHECK(mega.find(Squeezed("void kernel_Depth(uint tid, CRT_Hit hit)")) != std::string::npos);
  CHECK(mega.find(Squeezed("  CRT_Hit hit;\n  kernel_Hit(i, hit);\n  kernel_Depth(i, hit);\n")) != std::string::npos);
  CHECK(mega.find(Squeezed("readonly buffer crt_raysBuffer")) != std::string::npos);
  // Wavefront: kernel_Hit keeps the hit of each thread in a buffer; only it may use the hardware.
  const std::string hit = Squeezed(result.files.at("shaders/kernel_Hit.comp"));
  CHECK(hit.find(Squeezed("buffer crt_hitPerThreadBuffer { CRT_Hit hitPerThread[]; }")) != std::string::npos);
  CHECK(hit.find(Squeezed("hitPerThread[threadIndex] = hit;")) != std::string::npos);
  CHECK(result.files.count("shaders/kernel_Hit_RayQuery.comp") == 1);
  const std::string host = Squeezed(result.files.at("Tracer_Vulkan.cpp"));
  CHECK(host.find(Squeezed("Trace_MegakernelCmd(crt_cmd, n, crt_inOut_Trace.rays, crt_inOut_Trace.depth);")) != std::string::npos);
  CHECK(host.find(Squeezed("kernel_HitCmd(crt_cmd, n, crt_inOut_Trace.rays, crt_threadState.Trace_hit.View());")) != std::string::npos);
  // The megakernel reads the traversal's buffers even while kernel_Hit uses the hardware: they stay uploaded.
  CHECK(host.find(Squeezed("crt_vdata.m_pAccelStruct_m_nodes.Upload(")) != std::string::npos);
  CHECK(host.find(Squeezed("only the translated traversal reads it")) == std::string::npos);
}

TEST_CASE("On ISPC a thread loop runs as the megakernel's ISPC, and a loop nest around one kernel calls it, one thread a lane, chunks on all cores, or as the CPU class runs them", "[engine][modes][ispc]")
{
  TempClass tc("Walk", R"(#pragma once
#include "LiteMath.h"
#include <cstdint>
using LiteMath::float4;
class Walk
{
public:
  virtual ~Walk() = default;
  virtual void Run(uint32_t w, uint32_t h, int steps, [[crossrt::size("w * h")]] float4* out);
  virtual void Scale(uint32_t w, uint32_t h, float gain, float4* out);  // no size: the ISPC class reads it in place
  float4 m_step = float4(0.5f);
protected:
  void kernel_Start(uint32_t tidX, uint32_t tidY, float4* p);
  void kernel_Step(uint32_t tidX, uint32_t tidY, int k, float4* p);
  void kernel_Store(uint32_t tidX, uint32_t tidY, uint32_t w, const float4* p, float4* out);
  void kernel_Scale(uint32_t tidX, uint32_t tidY, uint32_t w, float gain, float4* out);
};
)",
               R"(#include "Walk.h"
void Walk::Run(uint32_t w, uint32_t h, int steps, float4* out)
{
  for (uint32_t y = 0; y < h; y++)
    for (uint32_t x = 0; x < w; x++)
    {
      float4 p;
      kernel_Start(x, y, &p);
      for (int k = 0; k < steps; k++)
        kernel_Step(x, y, k, &p);
      kernel_Store(x, y, w, &p, out);
    }
}
void Walk::kernel_Start(uint32_t tidX, uint32_t tidY, float4* p) { *p = float4(float(tidX), float(tidY), 0.0f, 1.0f); }
void Walk::kernel_Step(uint32_t, uint32_t, int k, float4* p) { *p = *p + m_step * float(k); }
void Walk::kernel_Store(uint32_t tidX, uint32_t tidY, uint32_t w, const float4* p, float4* out) { out[tidY * w + tidX] = *p; }
void Walk::Scale(uint32_t w, uint32_t h, float gain, float4* out)
{
  for (uint32_t y = 0; y < h; y++)
    for (uint32_t x = 0; x < w; x++)
      kernel_Scale(x, y, w, gain, out);
}
void Walk::kernel_Scale(uint32_t tidX, uint32_t tidY, uint32_t w, float gain, float4* out) { out[tidY * w + tidX] *= gain; }
)");
  const TranslateResult result = Translate(MakeRequest(tc, "Walk", Backend::Ispc));
  INFO(result.diagnostics);
  REQUIRE(result.ok);
  const std::string ispc = Squeezed(result.files.at("Walk_ISPC_kernels.ispc"));
  // The kernels take the per-thread values by reference, the buffers as pointers (`out` is a GLSL
  // word: out_), the class data first.
  CHECK(ispc.find(Squeezed("void kernel_Step(uniform Walk_Data *uniform self, uint tidX, uint tidY, int k, float4 &p)")) != std::string::npos);
  CHECK(ispc.find(Squeezed("void kernel_Store(uniform Walk_Data *uniform self, uint tidX, uint tidY, uint w, float4 p, "
                           "uniform float4 *uniform out_)")) != std::string::npos);
  // One thread: the locals start at zero, as LiteMath's do; the host loop runs in each lane.
  CHECK(ispc.find(Squeezed("float4 p = make_float4(0);\n  kernel_Start(self, x, y, p);\n  for (int k = 0; k < steps; k++)\n"
                           "  {\n    kernel_Step(self, x, y, k, p);\n  }\n  kernel_Store(self, x, y, w, p, out_);")) != std::string::npos);
  CHECK(ispc.find(Squeezed("export void Walk_Run_Megakernel(uniform Walk_Data *uniform self, uniform int crt_begin, uniform int crt_end, "
                           "uniform int crt_startX, uniform int crt_countX, uniform float4 *uniform out_, uniform int steps, uniform uint w)")) !=
        std::string::npos);
  CHECK(ispc.find(Squeezed("foreach_tiled (y = crt_begin ... crt_end, x = crt_startX ... crt_startX + crt_countX)")) != std::string::npos);
  // The control function hands chunks of rows to the cores in place of its loop.
  const std::string host = Squeezed(result.files.at("Walk_ISPC.cpp"));
  CHECK(host.find(Squeezed("crossrt::IspcPick(ispc::Walk_Run_Megakernel, {Walk_Run_Megakernel_sse4, Walk_Run_Megakernel_avx2, "
                           "Walk_Run_Megakernel_avx512skx})")) != std::string::npos);
  CHECK(host.find(Squeezed("crossrt::IspcPointer<ispc::float4*>(out), steps, w);")) != std::string::npos);
  // Or, where that has been faster here (crossrt::LaneChoice), the loop as the _CPU class runs it:
  // the lanes' chunks first, then the loop as written, on all cores.
  const size_t choice = host.find(Squeezed("static crossrt::LaneChoice crt_lanes(\"Walk::Run, a loop of it\"); crossrt::LaneChoice::Run crt_way = crt_lanes.Begin();"));
  const size_t lanes = host.find(Squeezed("if (crt_way.lanes) {"));
  const size_t scalar = host.find(Squeezed("kernel_Start(x, y, &p);"));
  CHECK(choice != std::string::npos);
  CHECK((choice < lanes && lanes != std::string::npos && lanes < scalar && scalar != std::string::npos));
  // (its rows in chunks of one on all cores)
  const size_t rows = host.find(Squeezed("crossrt::ParallelFor<"), lanes);
  CHECK(rows < scalar);
  CHECK(host.find(Squeezed("(crt_loop.parallel, 0, h, 1, [&]("), lanes) < scalar);
  // A loop nest around one kernel: its export function calls the kernel's thread function itself.
  CHECK(ispc.find(Squeezed("export void Walk_Scale_kernel_Scale(uniform Walk_Data *uniform self, uniform int crt_begin, uniform int crt_end, "
                           "uniform int crt_startX, uniform int crt_countX, uniform uint crt_w, uniform float crt_gain, uniform float4 *uniform crt_out_)")) !=
        std::string::npos);
  CHECK(ispc.find(Squeezed("kernel_Scale(self, (uint)crt_x, (uint)crt_y, crt_w, crt_gain, crt_out_);")) != std::string::npos);
  CHECK(host.find(Squeezed("crossrt::IspcPick(ispc::Walk_Scale_kernel_Scale,")) != std::string::npos);
  CHECK(host.find(Squeezed("uint32_t(w), float(gain), crossrt::IspcPointer<ispc::float4*>(out));")) != std::string::npos);
}

TEST_CASE("An error in the class's header fails the translation, on the first parse and on every reparse", "[engine]")
{
  // The header is parsed into the preamble, whose errors must count like the main file's.
  const std::string bad = R"(#pragma once
class Broken
{
public:
  virtual ~Broken() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out);
  undeclared_type m_oops;
protected:
  void kernel1D_Fill(int n, float* out);
};
)";
  TempClass tc("Broken", bad, R"(#include "Broken.h"
void Broken::Run(int n, float* out) { kernel1D_Fill(n, out); }
void Broken::kernel1D_Fill(int n, float* out) { for (int i = 0; i < n; i++) out[i] = 1.0f; }
)");
  AstCache cache;
  for (int parse = 0; parse < 2; ++parse)
  {
    INFO("parse " << parse);
    TranslateResult r = Translate(MakeRequest(tc, "Broken"), &cache);
    INFO(r.diagnostics);
    REQUIRE_FALSE(r.ok);
    REQUIRE(r.diagnostics.find("Broken.h:7:3: error: unknown type name 'undeclared_type'") != std::string::npos);
  }
  // Fixed, the same cache entry translates.
  std::string fixed = bad;
  fixed.replace(fixed.find("undeclared_type"), std::string("undeclared_type").size(), "float");
  std::ofstream(tc.Header("Broken")) << fixed;
  TranslateResult r = Translate(MakeRequest(tc, "Broken"), &cache);
  INFO(r.diagnostics);
  REQUIRE(r.ok);
}

TEST_CASE("An AST nothing has changed under serves the next translation as it is, and reports its errors again", "[engine]")
{
  TempClass tc("Heap", R"(#pragma once
class Heap
{
public:
  virtual ~Heap() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out);
protected:
  void kernel1D_Fill(int n, float* out);
};
)", R"(#include "Heap.h"
void Heap::Run(int n, float* out) { kernel1D_Fill(n, out); }
void Heap::kernel1D_Fill(int n, float* out) { for (int i = 0; i < n; i++) { float* p = new float[1]; p[0] = 1.0f; out[i] = p[0]; delete[] p; } }
)");
  AstCache cache;
  // Vulkan refuses the heap allocation, every time (30: past Clang's error limits, were they kept);
  // the CPU class takes it. One parse serves them all.
  for (int round = 0; round < 30; ++round)
  {
    INFO("round " << round);
    TranslateResult r = Translate(MakeRequest(tc, "Heap"), &cache);
    REQUIRE_FALSE(r.ok);
    REQUIRE(r.diagnostics.find("Heap.cpp:3:88: error: 'new' in a kernel (heap allocation)") != std::string::npos);
    REQUIRE(r.diagnostics.find("error: 'delete' in a kernel") != std::string::npos);
  }
  TranslateResult cpu = Translate(MakeRequest(tc, "Heap", Backend::Cpu), &cache);
  INFO(cpu.diagnostics);
  REQUIRE(cpu.ok);
  REQUIRE(cache.Stats().parses == 1);
  REQUIRE(cache.Stats().reuses == 30);
  // A header edited on disk: parsed again, and the edit is seen.
  std::ofstream(tc.Header("Heap"), std::ios::app) << "inline float Unused() { return 0.0f; }\n";
  REQUIRE(Translate(MakeRequest(tc, "Heap"), &cache).diagnostics.find("'new' in a kernel") != std::string::npos);
  REQUIRE(cache.Stats().reuses == 30);
  // Unsaved text stands for the source: the fix is seen without touching the disk, and reused as such.
  TranslateRequest fixed = MakeRequest(tc, "Heap");
  fixed.unsavedFiles[tc.Source("Heap")] = R"(#include "Heap.h"
void Heap::Run(int n, float* out) { kernel1D_Fill(n, out); }
void Heap::kernel1D_Fill(int n, float* out) { for (int i = 0; i < n; i++) out[i] = 1.0f; }
)";
  for (int round = 0; round < 2; ++round)
  {
    TranslateResult r = Translate(fixed, &cache);
    INFO(r.diagnostics);
    REQUIRE(r.ok);
  }
  REQUIRE(cache.Stats().reuses == 31);
  REQUIRE_FALSE(Translate(MakeRequest(tc, "Heap"), &cache).ok);  // the disk still has the allocation
}

TEST_CASE("The AST cache's preamble keeps the user's function bodies and knows every header it read", "[engine]")
{
  // The preamble drops the bodies of system headers' functions, not those of the user's helpers.
  TempClass tc("Doubler", R"(#pragma once
#include <vector>
class Doubler
{
public:
  virtual ~Doubler() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* out);
protected:
  void kernel1D_Run(int n, float* out);
};
)", R"(#include "Doubler.h"
#include "twice.h"
void Doubler::Run(int n, float* out) { kernel1D_Run(n, out); }
#include "offset.h"
void Doubler::kernel1D_Run(int n, float* out) { for (int i = 0; i < n; i++) out[i] = Twice(float(i)) + kOffset; }
)");
  fs::create_directories(tc.dir / "inc");
  std::ofstream(tc.dir / "inc" / "twice.h") << "#pragma once\ninline float Twice(float x) { return 2.0f * x; }\n";
  std::ofstream(tc.dir / "inc" / "offset.h") << "#pragma once\nconstexpr float kOffset = 0.5f;\n";
  AstCache cache;
  for (Backend backend : {Backend::Vulkan, Backend::Cpu})
    for (int parse = 0; parse < 2; ++parse)  // the first parse builds the preamble, the second reuses it
    {
      INFO("backend " << int(backend) << ", parse " << parse);
      TranslateRequest request = MakeRequest(tc, "Doubler", backend);
      request.compileArgs.push_back("-I" + (tc.dir / "inc").string());
      TranslateResult r = Translate(request, &cache);
      INFO(r.diagnostics);
      REQUIRE(r.ok);
      auto hasInput = [&](const std::string& suffix) {
        return std::any_of(r.inputs.begin(), r.inputs.end(), [&](const std::string& f) { return f.size() >= suffix.size() && f.compare(f.size() - suffix.size(), suffix.size(), suffix) == 0; });
      };
      CHECK(hasInput("/Doubler.cpp"));
      CHECK(hasInput("/Doubler.h"));
      CHECK(hasInput("/inc/twice.h"));
      CHECK(hasInput("/inc/offset.h"));       // included below the preamble
      CHECK(hasInput("/bits/stl_vector.h"));  // read for <vector>, though nothing in it is used
      if (backend == Backend::Vulkan)
      {
        std::string glsl;
        for (auto& [name, text] : r.files)
          if (name.find("kernel1D_Run") != std::string::npos && name.find("shaders/") == 0) glsl = text;
        CHECK(Squeezed(glsl).find("floatTwice(floatx)") != std::string::npos);
      }
      else  // the CPU source includes the helpers' header by the path the compiler found
        CHECK(r.files["Doubler_CPU.cpp"].find("#include \"" + (tc.dir / "inc" / "twice.h").string() + "\"") != std::string::npos);
      std::ofstream(tc.Source("Doubler"), std::ios::app) << "// an edit below the preamble\n";
    }
  // The same helper's header reached with -isystem (as CMake passes an imported target's): a clear error.
  TranslateRequest request = MakeRequest(tc, "Doubler");
  request.compileArgs.insert(request.compileArgs.end(), {"-isystem", (tc.dir / "inc").string()});
  TranslateResult r = Translate(request, &cache);
  CHECK_FALSE(r.ok);
  CHECK(r.diagnostics.find("Doubler.cpp:5:86: error: 'Twice' is declared in a system header") != std::string::npos);
  CHECK(r.diagnostics.find("-I, not -isystem") != std::string::npos);
}

// Level 3 in composed code (paper 3.10): the traversal's leaf calls become intersection shaders.
namespace {
const char* kLeafHeader = R"(#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <memory>
#include <vector>
struct Hit { float t; uint32_t id; };
struct IThing {
  virtual ~IThing() = default;
  virtual void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, uint32_t id, Hit& hit) const = 0;
  virtual LiteMath::float4 BoxMin() const = 0;
  virtual LiteMath::float4 BoxMax() const = 0;
};
struct Ball : IThing {
  LiteMath::float4 c;
  void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, uint32_t id, Hit& hit) const override {
    const float t = c.z - posAndNear.z;
    if (t >= posAndNear.w && t < hit.t) { hit.t = t; hit.id = id; }
  }
  LiteMath::float4 BoxMin() const override { return c; }
  LiteMath::float4 BoxMax() const override { return c; }
};
struct Plate : IThing {
  float z = 0.0f, pad = 0.0f;
  void Intersect(LiteMath::float4 posAndNear, LiteMath::float4, uint32_t id, Hit& hit) const override {
    if (z - posAndNear.z < hit.t) { hit.t = z - posAndNear.z; hit.id = id; }
  }
  LiteMath::float4 BoxMin() const override { return LiteMath::float4(-1.0f, -1.0f, z, 0.0f); }
  LiteMath::float4 BoxMax() const override { return LiteMath::float4(1.0f, 1.0f, z, 0.0f); }
};
struct IWorld { virtual ~IWorld() = default; virtual Hit Trace(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) = 0; };
struct World : IWorld {
  std::vector<std::shared_ptr<IThing>> m_things, m_lamps;
  Hit Trace(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) override;
};
class Leaves {
public:
  virtual ~Leaves() = default;
  virtual void Run(int n, [[crossrt::size("n")]] const LiteMath::float4* rays, [[crossrt::size("n")]] Hit* hits);
  virtual void CommitDeviceData() {}
protected:
  void kernel1D_Run(int n, const LiteMath::float4* rays, Hit* hits);
  std::shared_ptr<IWorld> m_world;
};
)";

std::string LeafSource(const std::string& loop) {
  return "#include \"Leaves.h\"\n"
         "Hit World::Trace(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) {\n"
         "  Hit hit;\n  hit.t = dirAndFar.w;\n  hit.id = ~0u;\n  uint32_t visited = 0;\n" + loop +
         "  return hit;\n}\n"
         "void Leaves::Run(int n, const LiteMath::float4* rays, Hit* hits) { kernel1D_Run(n, rays, hits); }\n"
         "void Leaves::kernel1D_Run(int n, const LiteMath::float4* rays, Hit* hits) {\n"
         "  for (int i = 0; i < n; ++i) hits[i] = m_world->Trace(rays[i], LiteMath::float4(0.0f, 0.0f, 1.0f, 100.0f));\n}\n";
}
}  // namespace

TEST_CASE("Level 3: a composed traversal's leaf calls become intersection shaders, or say why they cannot", "[engine][composition][virtual]")
{
  auto translate = [](const std::string& loop, int level, const std::string& header = kLeafHeader) {
    TempClass tc("Leaves", header, LeafSource(loop));
    TranslateRequest r = MakeRequest(tc, "Leaves");
    r.compositions = {"IWorld=World"};
    r.virtualLevel = level;
    return Translate(r);
  };
  const std::string visitAll = "  for (uint32_t i = 0; i < m_things.size(); ++i)\n    m_things[i]->Intersect(posAndNear, dirAndFar, i, hit);\n";
  {
    const TranslateResult result = translate(visitAll, 3);
    INFO(result.diagnostics);
    REQUIRE(result.ok);
    const std::string rgen = Squeezed(result.files.at("shaders/kernel1D_Run_Intersections.rgen"));
    const std::string rint = Squeezed(result.files.at("shaders/m_world_m_things_Ball_Intersect.rint"));
    // The loop is a trace from the traversal's ray up to the nearest hit so far; the rest is as written.
    CHECK(rgen.find(Squeezed("traceRayEXT(m_world_m_things_leaves, gl_RayFlagsNoneEXT, 0xFF, 0, 0, 0, posAndNear.xyz, crt_near, dirAndFar.xyz, hit.t, 0);")) != std::string::npos);
    CHECK(rgen.find(Squeezed("layout(location = 0) rayPayloadEXT Hit m_world_m_things_Intersect_hit;")) != std::string::npos);
    CHECK(rgen.find(Squeezed("hit.id = ~0u;")) != std::string::npos);
    CHECK(rgen.find(Squeezed("m_world_m_things_Intersect(")) == std::string::npos);  // no switch over the classes
    CHECK(Squeezed(result.files.at("shaders/kernel1D_Run.comp")).find(Squeezed("m_world_m_things_Intersect(uint(i)")) != std::string::npos);
    // The intersection shader: the leaf's object, Ball's Intersect on the hardware's ray, its index
    // the instance's, a report when nearer.
    CHECK(rint.find(Squeezed("objects[tag.y]")) != std::string::npos);
    CHECK(rint.find(Squeezed("Ball_Intersect(self, vec4(gl_WorldRayOriginEXT, gl_RayTminEXT), vec4(gl_WorldRayDirectionEXT, gl_RayTmaxEXT), uint(gl_InstanceID), hit);")) != std::string::npos);
    CHECK(rint.find(Squeezed("reportIntersectionEXT(hit.t, 0u);")) != std::string::npos);
    CHECK(result.files.count("shaders/m_world_m_things_Intersect_Hit.rchit") == 1);
    CHECK(result.files.count("shaders/m_world_m_things_Intersect_Miss.rmiss") == 1);
    const std::string host = Squeezed(result.files.at("Leaves_Vulkan.cpp"));
    CHECK(host.find(Squeezed("crt_scenes.m_world_m_things_leaves.BuildLeaves(leaves, \"Leaves::m_world->m_things\");")) != std::string::npos);
    CHECK(host.find(Squeezed("const auto lo = object->BoxMin(), hi = object->BoxMax();")) != std::string::npos);
  }
  // Two vectors of leaves, the second traced into its own hit: a trace each, on a scene, miss shader,
  // payload and range of hit groups each.
  {
    const TranslateResult result = translate(visitAll + "  Hit lamp = hit;\n  lamp.id = ~0u;\n"
                                             "  for (uint32_t j = 0; j < m_lamps.size(); ++j)\n    m_lamps[j]->Intersect(posAndNear, dirAndFar, j, lamp);\n"
                                             "  if (lamp.id != ~0u) { hit = lamp; hit.id += 1000u; }\n", 3);
    INFO(result.diagnostics);
    REQUIRE(result.ok);
    const std::string rgen = Squeezed(result.files.at("shaders/kernel1D_Run_Intersections.rgen"));
    CHECK(rgen.find(Squeezed("traceRayEXT(m_world_m_things_leaves, gl_RayFlagsNoneEXT, 0xFF, 0, 0, 0, posAndNear.xyz, crt_near, dirAndFar.xyz, hit.t, 0);")) != std::string::npos);
    // The lamps' hit groups follow the things' two (Ball, Plate).
    CHECK(rgen.find(Squeezed("traceRayEXT(m_world_m_lamps_leaves, gl_RayFlagsNoneEXT, 0xFF, 2, 0, 1, posAndNear.xyz, crt_near, dirAndFar.xyz, lamp.t, 1);")) != std::string::npos);
    CHECK(rgen.find(Squeezed("layout(location = 1) rayPayloadEXT Hit m_world_m_lamps_Intersect_hit;")) != std::string::npos);
    CHECK(rgen.find(Squeezed("uniform accelerationStructureEXT m_world_m_things_leaves;")) != std::string::npos);
    CHECK(rgen.find(Squeezed("uniform accelerationStructureEXT m_world_m_lamps_leaves;")) != std::string::npos);
    CHECK(rgen.find(Squeezed("hit.id += 1000u;")) != std::string::npos);  // the code after the loops is as written
    CHECK(result.files.count("shaders/m_world_m_lamps_Ball_Intersect.rint") == 1);
    CHECK(result.files.count("shaders/m_world_m_lamps_Intersect_Miss.rmiss") == 1);
    // The host: both vectors' boxes; in the pipeline's shaders, miss shader 1 and hit groups 2 and
    // 3 are the lamps'.
    const std::string host = Squeezed(result.files.at("Leaves_Vulkan.cpp"));
    CHECK(host.find(Squeezed("crt_scenes.m_world_m_lamps_leaves.BuildLeaves(leaves, \"Leaves::m_world->m_lamps\");")) != std::string::npos);
    const size_t shaders = host.find(Squeezed("crossrt::RayTracingShaders{"));
    REQUIRE(shaders != std::string::npos);
    std::vector<size_t> order;
    for (const char* shader : {"m_things_Intersect_Miss", "m_lamps_Intersect_Miss", "m_things_Ball_Intersect", "m_things_Plate_Intersect",
                               "m_lamps_Ball_Intersect", "m_lamps_Plate_Intersect"})
    {
      order.push_back(host.find(Squeezed(std::string("{Leaves_m_world_") + shader + "_spv"), shaders));
      INFO(shader);
      REQUIRE(order.back() != std::string::npos);
    }
    CHECK(std::is_sorted(order.begin(), order.end()));
  }
  // Two loops over the same vector with the same method share their payload, miss shader and hit groups.
  {
    const TranslateResult result = translate(visitAll + "  Hit again = hit;\n"
                                             "  for (uint32_t j = 0; j < m_things.size(); ++j)\n    m_things[j]->Intersect(posAndNear, dirAndFar, j, again);\n", 3);
    INFO(result.diagnostics);
    REQUIRE(result.ok);
    const std::string rgen = Squeezed(result.files.at("shaders/kernel1D_Run_Intersections.rgen"));
    CHECK(rgen.find(Squeezed("traceRayEXT(m_world_m_things_leaves, gl_RayFlagsNoneEXT, 0xFF, 0, 0, 0, posAndNear.xyz, crt_near, dirAndFar.xyz, hit.t, 0);")) != std::string::npos);
    CHECK(rgen.find(Squeezed("traceRayEXT(m_world_m_things_leaves, gl_RayFlagsNoneEXT, 0xFF, 0, 0, 0, posAndNear.xyz, crt_near, dirAndFar.xyz, again.t, 0);")) != std::string::npos);
    REQUIRE(rgen.find(Squeezed("rayPayloadEXT")) != std::string::npos);
    CHECK(rgen.find(Squeezed("rayPayloadEXT")) == rgen.rfind(Squeezed("rayPayloadEXT")));
    const std::string host = Squeezed(result.files.at("Leaves_Vulkan.cpp"));
    const size_t shaders = host.find(Squeezed("crossrt::RayTracingShaders{"));
    REQUIRE(shaders != std::string::npos);
    const std::string miss = "{Leaves_m_world_m_things_Intersect_Miss_spv", ball = "{Leaves_m_world_m_things_Ball_Intersect_spv";
    REQUIRE(host.find(Squeezed(miss), shaders) != std::string::npos);
    CHECK(host.find(Squeezed(miss), host.find(Squeezed(miss), shaders) + 1) == std::string::npos);  // one miss shader, one run of hit groups
    REQUIRE(host.find(Squeezed(ball), shaders) != std::string::npos);
    CHECK(host.find(Squeezed(ball), host.find(Squeezed(ball), shaders) + 1) == std::string::npos);
  }
  // The boxes may come from a public base of the interface, not from a private one.
  for (const std::string access : {"", "private "})
  {
    std::string header = kLeafHeader;
    const std::string boxes = "  virtual LiteMath::float4 BoxMin() const = 0;\n  virtual LiteMath::float4 BoxMax() const = 0;\n";
    REQUIRE(header.find(boxes) != std::string::npos);
    header.replace(header.find(boxes), boxes.size(), "");
    header.replace(header.find("struct IThing {"), std::string("struct IThing {").size(),
                   "struct IBounded {\n  virtual ~IBounded() = default;\n" + boxes + "};\nstruct IThing : " + access + "IBounded {");
    INFO(header);
    const TranslateResult result = translate(visitAll, 3, header);
    INFO(result.diagnostics);
    REQUIRE(result.ok);
    CHECK(result.files.count("shaders/kernel1D_Run_Intersections.rgen") == (access.empty() ? 1u : 0u));
    if (!access.empty())
      CHECK(Squeezed(result.files.at("Leaves_Vulkan.cpp")).find(Squeezed("IThing declares no public BoxMin() const and BoxMax() const (float3 or float4), nor inherits them")) !=
            std::string::npos);
  }
  // Level 2 asks for no ray tracing pipeline.
  {
    const TranslateResult result = translate(visitAll, 2);
    REQUIRE(result.ok);
    CHECK(result.files.count("shaders/kernel1D_Run_Intersections.rgen") == 0);
  }
  // Loops that do more than visit every leaf once keep the switch, and the host says why.
  const std::pair<std::string, std::string> kept[] = {
      {"  for (uint32_t i = 0; i < m_things.size(); ++i)\n    if (++visited > 0u) m_things[i]->Intersect(posAndNear, dirAndFar, i, hit);\n",
       "does more than visit leaves: it writes 'visited', declared before the loop"},
      {"  for (uint32_t i = 0; i < m_things.size(); ++i) {\n    m_things[i]->Intersect(posAndNear, dirAndFar, i, hit);\n    if (hit.id != ~0u) break;\n  }\n",
       "which visits every leaf once as the hardware does"},
      {"  for (uint32_t i = 1; i < m_things.size(); ++i)\n    m_things[i]->Intersect(posAndNear, dirAndFar, i, hit);\n",
       "is not 'for (i = 0; i < count; ++i) [if (box test)] Intersect(...);'"},
      {"  for (uint32_t i = 0; i < m_things.size(); ++i)\n    m_things[i]->Intersect(posAndNear, dirAndFar, i + 1, hit);\n",
       "argument 3 of m_world->m_things[...]->Intersect is neither the leaf's index nor a constant"},
      {"  m_things[0]->Intersect(posAndNear, dirAndFar, 0u, hit);\n", "is not inside a loop of the traversal's body"},
      // One loop the hardware could run is not enough: every leaf call must be one.
      {visitAll + "  m_lamps[0]->Intersect(posAndNear, dirAndFar, 0u, hit);\n", "m_world->m_lamps[...]->Intersect (Leaves.cpp:9) is not inside a loop"}};
  for (const auto& [loop, why] : kept)
  {
    INFO(loop);
    const TranslateResult result = translate(loop, 3);
    INFO(result.diagnostics);
    REQUIRE(result.ok);
    CHECK(result.files.count("shaders/kernel1D_Run_Intersections.rgen") == 0);
    const std::string host = Squeezed(result.files.at("Leaves_Vulkan.cpp"));
    const size_t said = host.find(Squeezed("still visits its leaves in software"));
    INFO((said == std::string::npos ? std::string("no reason given") : host.substr(said, host.find('\n', said) - said)));
    CHECK(host.find(Squeezed(why)) != std::string::npos);
  }
}

namespace
{
// The paper's form of listing 2: the traversal walks its own boxes and calls Intersect with a
// CRT_LeafInfo and itself; the object reads the traversal's values through it.
const char* kPaperLeafHeader = R"(#pragma once
#include "CrossRT.h"
#include "LiteMath.h"
#include <cstdint>
#include <memory>
#include <vector>
struct World;
struct IThing {
  virtual ~IThing() = default;
  virtual void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit, const World* world) const = 0;
};
struct Slab : IThing {
  float scale = 1.0f;
  void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit, const World* world) const override;
};
struct IWorld { virtual ~IWorld() = default; virtual CRT_Hit Trace(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) = 0; };
struct World : IWorld {
  std::vector<std::shared_ptr<IThing>> m_things;
  std::vector<float> m_depths;           // per box
  std::vector<LiteMath::uint2> m_boxes;  // (thing, box)
  CRT_Hit Trace(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) override;
  float Depth(uint32_t box) const { return m_depths[box]; }
  BOXES
};
class Leaves {
public:
  virtual ~Leaves() = default;
  virtual void Run(int n, [[crossrt::size("n")]] const LiteMath::float4* rays, [[crossrt::size("n")]] CRT_Hit* hits);
  virtual void CommitDeviceData() {}
protected:
  void kernel1D_Run(int n, const LiteMath::float4* rays, CRT_Hit* hits);
  std::shared_ptr<IWorld> m_world;
};
)";

std::string PaperLeafSource(const std::string& after) {
  return "#include \"Leaves.h\"\n"
         "void Slab::Intersect(LiteMath::float4 posAndNear, LiteMath::float4, CRT_LeafInfo info, CRT_Hit& hit, const World* world) const {\n"
         "  const float t = scale * world->Depth(info.aabbId) - posAndNear.z + 0.0f * world->m_depths[0];\n"
         "  if (t >= posAndNear.w && t < hit.t) { hit.t = t; hit.primId = info.aabbId; hit.geomId = info.geomId; }\n}\n"
         "CRT_Hit World::Trace(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) {\n"
         "  CRT_Hit hit;\n  hit.t = dirAndFar.w;\n  hit.primId = ~0u;\n  hit.instId = 0u;\n  hit.geomId = ~0u;\n"
         "  uint32_t visited = 0;\n  uint32_t next = 0;\n"
         "  while (next < m_boxes.size()) {\n"
         "    CRT_LeafInfo info;\n    info.geomId = m_boxes[next].x;\n    info.aabbId = m_boxes[next].y;\n    ++visited;\n    ++next;\n"
         "    m_things[info.geomId]->Intersect(posAndNear, dirAndFar, info, hit, this);\n  }\n" + after +
         "  return hit;\n}\n"
         "void Leaves::Run(int n, const LiteMath::float4* rays, CRT_Hit* hits) { kernel1D_Run(n, rays, hits); }\n"
         "void Leaves::kernel1D_Run(int n, const LiteMath::float4* rays, CRT_Hit* hits) {\n"
         "  for (int i = 0; i < n; ++i) hits[i] = m_world->Trace(rays[i], LiteMath::float4(0.0f, 0.0f, 1.0f, 100.0f));\n}\n";
}
}  // namespace

TEST_CASE("Level 3 in the paper's form: a traversal passing CRT_LeafInfo and itself becomes a trace over each object's leaf boxes", "[engine][composition][virtual]")
{
  const std::string boxes = "std::vector<CRT_AABB> LeafBoxes(uint32_t thing) const;";
  auto translate = [](const std::string& after, const std::string& boxesDecl) {
    std::string header = kPaperLeafHeader;
    header.replace(header.find("BOXES"), 5, boxesDecl);
    TempClass tc("Leaves", header, PaperLeafSource(after));
    TranslateRequest r = MakeRequest(tc, "Leaves");
    r.compileArgs.push_back("-I" CROSSRT_SOURCE_DIR "/libs/litert");  // CrossRT.h: CRT_LeafInfo, CRT_Hit, CRT_AABB
    r.compositions = {"IWorld=World"};
    r.virtualLevel = 3;
    return Translate(r);
  };
  {
    const TranslateResult result = translate("", boxes);
    INFO(result.diagnostics);
    REQUIRE(result.ok);
    // The switch of level 2 takes no `this`: the traversal's data are the kernel's buffers.
    const std::string comp = Squeezed(result.files.at("shaders/kernel1D_Run.comp"));
    CHECK(comp.find(Squeezed("m_world_m_things_Intersect(uint(info.geomId), posAndNear, dirAndFar, info, hit);")) != std::string::npos);
    CHECK(comp.find(Squeezed("const float t = self.scale * m_world_Depth(info.aabbId) - posAndNear.z + 0.0 * m_world_m_depths[0u];")) != std::string::npos);
    // The whole walk is the hardware's: the loop is a trace.
    const std::string rgen = Squeezed(result.files.at("shaders/kernel1D_Run_Intersections.rgen"));
    CHECK(rgen.find(Squeezed("traceRayEXT(m_world_m_things_leaves, gl_RayFlagsNoneEXT, 0xFF, 0, 0, 0, posAndNear.xyz, crt_near, dirAndFar.xyz, hit.t, 0);")) != std::string::npos);
    CHECK(rgen.find(Squeezed("while (next <")) == std::string::npos);
    // The intersection shader: the object from the instance's custom index, the info from the
    // hardware, the object ray, and the traversal's buffer at the kernel's binding.
    const std::string rint = Squeezed(result.files.at("shaders/kernel1D_Run_m_world_m_things_Slab_Intersect.rint"));
    CHECK(rint.find(Squeezed("const uint crt_element = uint(gl_InstanceCustomIndexEXT);")) != std::string::npos);
    CHECK(rint.find(Squeezed("crt_info.aabbId = uint(gl_PrimitiveID);")) != std::string::npos);
    CHECK(rint.find(Squeezed("crt_info.geomId = crt_element;")) != std::string::npos);
    CHECK(rint.find(Squeezed("Slab_Intersect(self, vec4(gl_ObjectRayOriginEXT, gl_RayTminEXT), vec4(gl_ObjectRayDirectionEXT, gl_RayTmaxEXT), crt_info, hit);")) !=
          std::string::npos);
    const size_t inComp = comp.find(Squeezed("buffer crt_m_world_m_depthsBuffer")), inRint = rint.find(Squeezed("buffer crt_m_world_m_depthsBuffer"));
    REQUIRE(inComp != std::string::npos);
    REQUIRE(inRint != std::string::npos);
    const auto bindingBefore = [](const std::string& text, size_t at) {  // "binding=N)"
      const size_t from = text.rfind("binding", at);
      return text.substr(from, text.find(')', from) + 1 - from);
    };
    CHECK(bindingBefore(comp, inComp) == bindingBefore(rint, inRint));
    // The host builds a bottom level per object over the boxes the traversal gives.
    const std::string host = Squeezed(result.files.at("Leaves_Vulkan.cpp"));
    CHECK(host.find(Squeezed("for (const auto& box : crt_m_world()->LeafBoxes(uint32_t(i)))")) != std::string::npos);
    CHECK(host.find(Squeezed("crt_scenes.m_world_m_things_leaves.BuildBoxGeometries(geometries,")) != std::string::npos);
  }
  // What the hardware's walk cannot give keeps the switch, and the host says why.
  const std::pair<std::string, std::string> kept[] = {
      {"", "World declares no public 'std::vector<CRT_AABB> LeafBoxes(uint32_t geomId) const'"},
      {"  if (visited == 0u) hit.instId = 1u;\n", "the traversal's loop writes 'visited' (Leaves.cpp:18), read after it"}};
  for (const auto& [after, why] : kept)
  {
    INFO(why);
    const TranslateResult result = translate(after, after.empty() ? "" : boxes);
    INFO(result.diagnostics);
    REQUIRE(result.ok);
    CHECK(result.files.count("shaders/kernel1D_Run_Intersections.rgen") == 0);
    const std::string host = Squeezed(result.files.at("Leaves_Vulkan.cpp"));
    const size_t said = host.find(Squeezed("still visits its leaves in software"));
    INFO((said == std::string::npos ? std::string("no reason given") : host.substr(said, host.find('\n', said) - said)));
    CHECK(host.find(Squeezed(why)) != std::string::npos);
  }
}

TEST_CASE("Names a user gives that GLSL reserves come out renamed: a parameter 'image', a local 'length', a field 'sample'", "[engine]")
{
  const char* header = R"(#pragma once
#include "LiteMath.h"
#include <cstdint>
struct Tap { float sample; float step; };
class Names
{
public:
  virtual ~Names() = default;
  virtual void Run(int n, [[crossrt::size("n")]] const Tap* taps, [[crossrt::size("n")]] uint32_t* image);
protected:
  void kernel1D_Run(int n, const Tap* taps, uint32_t* image);
};
)";
  const char* source = R"(#include "Names.h"
void Names::Run(int n, const Tap* taps, uint32_t* image) { kernel1D_Run(n, taps, image); }
void Names::kernel1D_Run(int n, const Tap* taps, uint32_t* image)
{
  for (int i = 0; i < n; ++i)
  {
    const float length = taps[i].sample + LiteMath::length(LiteMath::float2(taps[i].step, 1.0f));
    image[i] = uint32_t(length);
  }
}
)";
  TempClass tc("Names", header, source);
  TranslateResult r = Translate(MakeRequest(tc, "Names"));  // the translation compiles its shaders: it fails if GLSL rejects them
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  const std::string glsl = Squeezed(r.files.at("shaders/kernel1D_Run.comp"));
  CHECK(glsl.find(Squeezed("buffer crt_imageBuffer")) != std::string::npos);  // not GLSL's imageBuffer type: prefixed
  CHECK(glsl.find(Squeezed("float sample_;")) != std::string::npos);
  CHECK(glsl.find(Squeezed("const float length_ = taps[i].sample_ + length(vec2(taps[i].step_, 1.0));")) != std::string::npos);
  CHECK(glsl.find(Squeezed("image[i] = uint(length_);")) != std::string::npos);
}

TEST_CASE("ISPC: a composed object's scalar members are shared by the gang: CRT_UNIFORM locals take them, and loops they bound are uniform", "[engine][composition][ispc]")
{
  TempClass tc("Summer", R"(#pragma once
#include "Gang.h"
#include <cstdint>
#include <memory>
#include <vector>
struct IField { virtual ~IField() = default; virtual float Sum(float x) const = 0; };
struct Field : IField {
  std::vector<float> m_values;
  int m_count = 0;
  float Sum(float x) const override;
};
class Summer {
public:
  virtual ~Summer() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* data);
  virtual void CommitDeviceData() {}
protected:
  void kernel1D_Run(int n, float* data);
  std::shared_ptr<IField> m_field;
};
)",
               R"(#include "Summer.h"
float Field::Sum(float x) const
{
  CRT_UNIFORM const int count = m_count;
  float s = x;
  for (int k = 0; k < count; ++k)
    s += m_values[k];
  for (int k = 0; k < m_count; ++k)
    s += m_values[k];
  return s;
}
void Summer::Run(int n, float* data) { kernel1D_Run(n, data); }
void Summer::kernel1D_Run(int n, float* data)
{
  for (int i = 0; i < n; ++i)
    data[i] = m_field->Sum(data[i]);
}
)");
  TranslateRequest r = MakeRequest(tc, "Summer", Backend::Ispc);
  r.compositions = {"IField=Field"};
  const TranslateResult result = Translate(r);
  INFO(result.diagnostics);
  REQUIRE(result.ok);
  const std::string ispc = Squeezed(result.files.at("Summer_ISPC_kernels.ispc"));
  INFO(ispc);
  CHECK(ispc.find(Squeezed("const uniform int count = self->m_field_m_count;")) != std::string::npos);
  CHECK(ispc.find(Squeezed("for (uniform int k = 0; k < count; ++k)")) != std::string::npos);
  CHECK(ispc.find(Squeezed("for (uniform int k = 0; k < self->m_field_m_count; ++k)")) != std::string::npos);
}

TEST_CASE("ISPC: a loop is shared where its start is and its condition is, given its variable shared (k + 1 < top, 2 * k < n)", "[engine][ispc]")
{
  TempClass tc("Sorter", R"(#pragma once
#include "Gang.h"
class Sorter {
public:
  virtual ~Sorter() = default;
  virtual void Run(int n, [[crossrt::size("n")]] float* data);
  virtual void CommitDeviceData() {}
protected:
  void kernel1D_Run(int n, float* data);
  int m_rounds = 2;
};
)",
               R"(#include "Sorter.h"
void Sorter::Run(int n, float* data) { kernel1D_Run(n, data); }
void Sorter::kernel1D_Run(int n, float* data)
{
  for (int i = 0; i < n; ++i)
  {
    CRT_UNIFORM int keys[4] = {3, 1, 2, 0};
    CRT_UNIFORM const int top = 4;
    CRT_UNIFORM const int below = top - 3;
    // a pass of bubble sort over keys[below, top): the gang swaps the shared keys together
    for (int k = below; k + 1 < top; ++k)
    {
      if (keys[k] > keys[k + 1])
      {
        CRT_UNIFORM const int kept = keys[k];
        keys[k] = keys[k + 1];
        keys[k + 1] = kept;
      }
    }
    float s = data[i];
    for (int k = 0; 2 * k < m_rounds; ++k)
      s += float(keys[k]);
    for (int k = 0; k + i < n && k < 3; ++k)  // bound by the thread's index: not shared
      s += 0.5f;
    data[i] = s;
  }
}
)");
  const TranslateResult result = Translate(MakeRequest(tc, "Sorter", Backend::Ispc));
  INFO(result.diagnostics);
  REQUIRE(result.ok);
  const std::string ispc = Squeezed(result.files.at("Sorter_ISPC_kernels.ispc"));
  INFO(ispc);
  CHECK(ispc.find(Squeezed("for (uniform int k = below; k + 1 < top; ++k)")) != std::string::npos);
  CHECK(ispc.find(Squeezed("for (uniform int k = 0; 2 * k < self->m_rounds; ++k)")) != std::string::npos);
  CHECK(ispc.find(Squeezed("for (int k = 0; k + i < n && k < 3; ++k)")) != std::string::npos);
}
