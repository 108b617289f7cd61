// Cases about pointers in kernels and helpers: a generator's state by pointer, out parameters,
// p->field, row pointers, data() in kernels, and locals whose addresses a per-thread function
// passes to kernels (kernel_slicer's RTV form).
#include "Conformance.h"

#include "LiteMath.h"

// A case compiles where this build translated its class (CONFORMANCE_CLASSES); main checks that all were.
#if __has_include("ParticleRefs_CPU.h")
#include "ParticleRefs_CPU.h"
#include "ParticleRefs_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "ParticleRefs_ISPC.h"
#endif
#endif
#if __has_include("PixelRows_CPU.h")
#include "PixelRows_CPU.h"
#include "PixelRows_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "PixelRows_ISPC.h"
#endif
#endif
#if __has_include("NoisyFill_CPU.h")
#include "NoisyFill_CPU.h"
#include "NoisyFill_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "NoisyFill_ISPC.h"
#endif
#endif
#if __has_include("MinMaxPair_CPU.h")
#include "MinMaxPair_CPU.h"
#include "MinMaxPair_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "MinMaxPair_ISPC.h"
#endif
#endif
#if __has_include("ParticleStep_CPU.h")
#include "ParticleStep_CPU.h"
#include "ParticleStep_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "ParticleStep_ISPC.h"
#endif
#endif
#if __has_include("RowSums_CPU.h")
#include "RowSums_CPU.h"
#include "RowSums_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "RowSums_ISPC.h"
#endif
#endif
#if __has_include("Gather_CPU.h")
#include "Gather_CPU.h"
#include "Gather_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Gather_ISPC.h"
#endif
#endif
#if __has_include("BodiesOut_CPU.h")
#include "BodiesOut_CPU.h"
#include "BodiesOut_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "BodiesOut_ISPC.h"
#endif
#endif
#if __has_include("LayerBlock_CPU.h")
#include "LayerBlock_CPU.h"
#include "LayerBlock_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "LayerBlock_ISPC.h"
#endif
#endif
#if __has_include("PixelBlock_CPU.h")
#include "PixelBlock_CPU.h"
#include "PixelBlock_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "PixelBlock_ISPC.h"
#endif
#endif
#if __has_include("SaxpyNames_CPU.h")
#include "SaxpyNames_CPU.h"
#include "SaxpyNames_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "SaxpyNames_ISPC.h"
#endif
#endif
#if __has_include("LoopSized_CPU.h")
#include "LoopSized_CPU.h"
#include "LoopSized_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "LoopSized_ISPC.h"
#endif
#endif
#if __has_include("SaxpyBlock_CPU.h")
#include "SaxpyBlock_CPU.h"
#include "SaxpyBlock_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "SaxpyBlock_ISPC.h"
#endif
#endif

using namespace conformance;
using LiteMath::float4;

namespace {

std::vector<float> Wave(int n, float phase) {
  std::vector<float> v(n);
  for (int i = 0; i < n; i++) v[i] = std::sin(0.37f * float(i) + phase) * 10.0f;
  return v;
}

#if __has_include("NoisyFill_CPU.h")
Register noisyFill(MakeCase<NoisyFill>(
    "RandomGen* passed to helpers that advance it (gen->state)", "random_gen.h/.cpp", 1e-6, CONFORMANCE_MAKERS(NoisyFill, 512u),
    [](NoisyFill& f) {
      std::vector<float> out(512, 0.0f);
      f.CommitDeviceData();
      f.Fill(512, out.data(), 5);
      Outputs r;
      Append(r, out);
      for (auto& g : f.m_gens) r.insert(r.end(), {double(g.state.x), double(g.state.y)});
      return r;
    }));
#endif

#if __has_include("MinMaxPair_CPU.h")
Register minMaxPair(MakeCase<MinMaxPair>(
    "&local passed to a helper's out parameters (*lo = ..., hi[0] = ...)", "min_max_pair.h/.cpp", 0.0, CONFORMANCE_MAKERS(MinMaxPair),
    [](MinMaxPair& m) {
      const int n = 700;
      std::vector<float> a = Wave(n, 0.0f), b = Wave(n, 1.0f), lo(n), hi(n);
      m.Run(n, a.data(), b.data(), lo.data(), hi.data());
      Outputs r;
      Append(r, lo);
      Append(r, hi);
      return r;
    }));
#endif

#if __has_include("ParticleStep_CPU.h")
Register particles(MakeCase<ParticleStep>(
    "&m_vec[i] passed to a static member helper that writes p->field", "particles.h/.cpp", 1e-5, CONFORMANCE_MAKERS(ParticleStep),
    [](ParticleStep& p) {
      p.m_particles.resize(256);
      // Every seventh particle starts just above the ground, falling: it bounces in the first step
      // (a bounce decided by rounding would make the backends part ways, so none is close).
      for (int i = 0; i < 256; i++)
        p.m_particles[i] = i % 7 == 0 ? Particle{float4(float(i % 16), 0.001f, 0.0f, 1.0f), float4(1.0f, -3.0f, 0.5f, 0.0f)}
                                      : Particle{float4(float(i % 16), 5.0f + float(i % 7), 0.0f, 1.0f), float4(1.0f, float(i % 5), 0.5f, 0.0f)};
      p.CommitDeviceData();
      p.Step(0.01f, 10);
      Outputs r;
      for (auto& q : p.m_particles) Append(r, std::vector<float>{q.pos.x, q.pos.y, q.pos.z, q.vel.y});
      return r;
    }));
#endif

#if __has_include("RowSums_CPU.h")
Register rowSums(MakeCase<RowSums>(
    "a row pointer into a buffer: const float* row = a_in + y * w; row[x], *row", "row_sums.h/.cpp", 1e-5, CONFORMANCE_MAKERS(RowSums),
    [](RowSums& s) {
      const int w = 33, h = 40;
      std::vector<float> in = Wave(w * h, 0.5f), sums(h);
      s.Sum(w, h, in.data(), sums.data());
      Outputs r;
      Append(r, sums);
      return r;
    }));
#endif

#if __has_include("Gather_CPU.h")
Register gather(MakeCase<Gather>(
    "m_vec.data() in a kernel, and data() + 2 handed to a static helper", "gather.h/.cpp", 0.0, CONFORMANCE_MAKERS(Gather), [](Gather& g) {
      g.CommitDeviceData();
      std::vector<float> out(300);
      g.Run(300, out.data());
      Outputs r;
      Append(r, out);
      return r;
    }));
#endif

#if __has_include("PixelRows_CPU.h")
Register pixelRows(MakeCase<PixelRows>(
    "float4/int4 pixels stored in order, mirrored, and rows[k++] += v, local[k++] += v", "pixel_rows.h/.cpp", 0.0, CONFORMANCE_MAKERS(PixelRows),
    [](PixelRows& p) {
      const int n = 1001;
      std::vector<float4> in(n), rows(n), mirrored(n);
      std::vector<int4> cells(n);
      for (int i = 0; i < n; i++) in[i] = float4(0.25f * float(i), float(i % 13), -float(i), 0.5f);
      p.Shade(n, in.data(), rows.data(), mirrored.data(), cells.data());
      Outputs r;
      for (int i = 0; i < n; i++) {
        Append(r, std::vector<float>{rows[i].x, rows[i].y, rows[i].z, rows[i].w, mirrored[i].x, mirrored[i].y, mirrored[i].z, mirrored[i].w});
        Append(r, std::vector<int>{cells[i].x, cells[i].y, cells[i].z, cells[i].w});
      }
      return r;
    }));
#endif

#if __has_include("SaxpyBlock_CPU.h")
Register saxpyBlock(MakeCase<SaxpyBlock>(
    "a per-thread function passing &local to kernels, run by a ...Block loop (RTV)", "saxpy_block.h/.cpp", 1e-6, CONFORMANCE_MAKERS(SaxpyBlock),
    [](SaxpyBlock& s) {
      const uint32_t n = 1500;
      std::vector<float> x = Wave(n, 0.2f), y = Wave(n, 2.0f), out(n);
      s.RunBlock(n, 0.75f, x.data(), y.data(), out.data());
      Outputs r;
      Append(r, out);
      return r;
    }));
#endif

#if __has_include("SaxpyNames_CPU.h")
Register saxpyNames(MakeCase<SaxpyNames>(
    "two kernels of a thread loop whose parameters of one name get different buffers (wavefront in both modes)", "saxpy_names.h/.cpp", 1e-6,
    CONFORMANCE_MAKERS(SaxpyNames), [](SaxpyNames& s) {
      const unsigned n = 777;
      std::vector<float> a = Wave(int(n), 0.1f), b = Wave(int(n), 1.3f), c = Wave(int(n), 2.9f), out(n, -1.0f);
      Outputs r;
      s.SaxpyBlock(a.data(), b.data(), c.data(), out.data(), n);  // (SaxpyNames_Vulkan has no megakernel to switch to)
      Append(r, out);
      return r;
    }));
#endif

#if __has_include("LoopSized_CPU.h")
Register loopSized(MakeCase<LoopSized>(
    "pointers without a size, handed to kernels that index them by their loop's variable (the loop gives the size)", "loop_sized.h/.cpp", 1e-6,
    CONFORMANCE_MAKERS(LoopSized), [](LoopSized& l) {
      l.CommitDeviceData();
      Outputs r;
      std::vector<int> data(97);
      for (size_t i = 0; i < data.size(); ++i) data[i] = int(i * 37 % 23) - 9;
      l.Sum(data.data(), unsigned(data.size() - 1));  // its last element counts too (i <= a_last)
      Append(r, std::vector<float>{float(l.m_sum)});
      std::vector<float> in(61), out(61, -1.0f);
      for (size_t i = 0; i < in.size(); ++i) in[i] = 0.25f * float(i) - 3.0f;
      l.Scale(in.data(), out.data(), uint32_t(in.size()));
      Append(r, out);
      return r;
    }));
#endif

#if __has_include("BodiesOut_CPU.h")
Register bodiesOut(MakeCase<BodiesOut>(
    "an output pointer without a size that only host code fills (memcpy from a member vector after the kernels)", "bodies_out.h/.cpp", 1e-5,
    CONFORMANCE_MAKERS(BodiesOut), [](BodiesOut& b) {
      b.CommitDeviceData();
      Outputs r;
      for (uint32_t steps : {3u, 5u}) {  // twice, the host reading m_steps each time
        b.SetSteps(steps);
        std::vector<BodyState> out(b.m_bodies.size());
        b.Perform(out.data());
        for (const BodyState& s : out) Append(r, std::vector<float>{s.posAndMass.x, s.posAndMass.y, s.velocity.x, s.velocity.y});
      }
      return r;
    }));
#endif

#if __has_include("LayerBlock_CPU.h")
Register layerBlock(MakeCase<LayerBlock>(
    "...Block loops: a constant for a loop bound under a name the Block has too, size(\"tid\") on the per-thread function", "layer_block.h/.cpp", 1e-6,
    CONFORMANCE_MAKERS(LayerBlock), [](LayerBlock& b) {
      Outputs r;
      for (auto mode : {crossrt::ExecutionMode::Megakernel, crossrt::ExecutionMode::Wavefront}) {  // both ways on Vulkan
        if (auto* gpu = dynamic_cast<LayerBlock_Vulkan*>(&b)) gpu->SetExecutionMode(mode);
        std::vector<float> out(300);
        for (size_t i = 0; i < out.size(); i++) out[i] = 0.25f * float(i % 7);
        b.AddBlock(uint32_t(out.size()), 5, out.data());
        b.QuarterBlock(out.data(), 200);  // the first 200 only
        Append(r, out);
      }
      return r;
    }));
#endif

#if __has_include("PixelBlock_CPU.h")
Register pixelBlock(MakeCase<PixelBlock>(
    "a ...Block loop whose output's size is on the per-thread function it runs (kernel_slicer's MainFunc/MainFuncBlock)", "pixel_block.h/.cpp", 0.0,
    CONFORMANCE_MAKERS(PixelBlock), [](PixelBlock& p) {
      Outputs r;
      for (auto mode : {crossrt::ExecutionMode::Megakernel, crossrt::ExecutionMode::Wavefront}) {  // both ways on Vulkan
        if (auto* gpu = dynamic_cast<PixelBlock_Vulkan*>(&p)) gpu->SetExecutionMode(mode);
        std::vector<uint32_t> colors(48 * 32, 0xdeadbeefu);
        p.MainFuncBlock(48, 32, colors.data(), 2);
        Append(r, std::vector<double>(colors.begin(), colors.end()));
      }
      return r;
    }));
#endif

#if __has_include("ParticleRefs_CPU.h")
Register particleRefs(MakeCase<ParticleRefs>(
    "references to m_bodies and its element written through, float& to a local's element, assert, std::swap, std::max({...}), std::array", "particle_refs.h/.cpp", 1e-5,
    CONFORMANCE_MAKERS(ParticleRefs), [](ParticleRefs& p) {
      p.CommitDeviceData();
      for (int step = 0; step < 3; step++) p.Advance(200, 0.01f);  // each call reads the bodies back
      Outputs r;
      for (const Body& b : p.m_bodies) Append(r, std::vector<float>{b.pos.x, b.pos.y, b.pos.z, b.vel.y, b.age});
      return r;
    }));
#endif

}  // namespace
