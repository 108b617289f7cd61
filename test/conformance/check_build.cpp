// Cases about how a class is declared and built: size annotations, destructors, control functions
// that are not virtual, headers.
#include "Conformance.h"

#include "LiteMath.h"

// A case compiles where this build translated its class (CONFORMANCE_CLASSES); main checks that all were.
#if __has_include("ImageScale_CPU.h")
#include "ImageScale_CPU.h"
#include "ImageScale_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "ImageScale_ISPC.h"
#endif
#endif
#if __has_include("Saxpy_CPU.h")
#include "Saxpy_CPU.h"
#include "Saxpy_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Saxpy_ISPC.h"
#endif
#endif
#if __has_include("Brighten_CPU.h")
#include "Brighten_CPU.h"
#include "Brighten_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Brighten_ISPC.h"
#endif
#endif
#if __has_include("Accumulate_CPU.h")
#include "Accumulate_CPU.h"
#include "Accumulate_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Accumulate_ISPC.h"
#endif
#endif
#if __has_include("Decay_CPU.h")
#include "Decay_CPU.h"
#include "Decay_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Decay_ISPC.h"
#endif
#endif
#if __has_include("BoxBlur_CPU.h")
#include "BoxBlur_CPU.h"
#include "BoxBlur_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "BoxBlur_ISPC.h"
#endif
#endif

using namespace conformance;

namespace {

std::vector<float> Ramp(int n, float scale) {
  std::vector<float> v(n);
  for (int i = 0; i < n; i++) v[i] = scale * float((i * 37) % 101) - 20.0f;
  return v;
}

#if __has_include("ImageScale_CPU.h")
Register imageScale(MakeCase<ImageScale>(
    "size(\"w\", \"h\"): several strings multiply", "size_product.h/.cpp", 1e-6, CONFORMANCE_MAKERS(ImageScale), [](ImageScale& s) {
      const int w = 37, h = 23;
      std::vector<float> in = Ramp(w * h, 0.5f), out(w * h, -1.0f);
      s.Scale(w, h, in.data(), out.data());
      Outputs r;
      Append(r, out);
      return r;
    }));
#endif

#if __has_include("Saxpy_CPU.h")
Register saxpy(MakeCase<Saxpy>(
    "[[size(\"n\")]]: the unscoped C++11 spelling", "unscoped_size.h/.cpp", 1e-6, CONFORMANCE_MAKERS(Saxpy, 1.5f), [](Saxpy& s) {
      const uint32_t n = 1000;
      std::vector<float> x = Ramp(n, 0.25f), y = Ramp(n, -0.5f), out(n, 0.0f);
      s.Run(n, x.data(), y.data(), out.data());
      Outputs r;
      Append(r, out);
      return r;
    }));
#endif

#if __has_include("Brighten_CPU.h")
Register brighten(MakeCase<Brighten>(
    "a class without a virtual destructor", "no_virtual_destructor.h/.cpp", 1e-6, CONFORMANCE_MAKERS(Brighten), [](Brighten& b) {
      b.m_tint = {LiteMath::float4(1.0f, 0.5f, 2.0f, 1.0f), LiteMath::float4(0.25f, 1.0f, 1.0f, 3.0f), LiteMath::float4(2.0f)};
      b.CommitDeviceData();
      std::vector<LiteMath::float4> pixels(300);
      for (int i = 0; i < 300; i++) pixels[i] = LiteMath::float4(float(i), float(i % 7), 1.0f, 0.5f);
      b.Apply(300, pixels.data());
      Outputs r;
      for (auto& p : pixels) Append(r, std::vector<float>{p.x, p.y, p.z, p.w});
      return r;
    }));

// Called through a pointer to the generated class, the non-virtual control function runs translated;
// GetExecutionTime (virtual) tells which one ran: the original times nothing.
#endif

#if __has_include("Accumulate_CPU.h")
Register accumulate(MakeCase<Accumulate>(
    "a control function that is not virtual (warning; the generated one hides it)", "non_virtual_control.h/.cpp", 1e-6,
    [] { return std::make_shared<Accumulate>(); }, [] { return CreateAccumulate_CPU(); },
    [] { return CreateAccumulate_Vulkan(Context()); }, CONFORMANCE_ISPC_MAKER(Accumulate, ),
    [](Accumulate& a) {
      const int n = 500;
      std::vector<float> in = Ramp(n, 1.0f), acc(n, 1.0f);
      bool translated = true;
      if (auto* cpu = dynamic_cast<Accumulate_CPU*>(&a)) cpu->AddInto(n, in.data(), acc.data());
      else if (auto* gpu = dynamic_cast<Accumulate_Vulkan*>(&a)) gpu->AddInto(n, in.data(), acc.data());
#ifdef CONFORMANCE_ISPC
      else if (auto* simd = dynamic_cast<Accumulate_ISPC*>(&a)) simd->AddInto(n, in.data(), acc.data());
#endif
      else {
        a.AddInto(n, in.data(), acc.data());
        translated = false;
      }
      float times[4];
      a.GetExecutionTime("AddInto", times);
      Outputs r;
      Append(r, acc);
      r.push_back(translated ? double(times[3] > 0.0f) : 1.0);
      return r;
    }));
#endif

#if __has_include("Decay_CPU.h")
Register decay(MakeCase<Decay>(
    "a header that includes only LiteMath.h and <vector>", "minimal_headers.h/.cpp", 1e-6, CONFORMANCE_MAKERS(Decay), [](Decay& d) {
      d.m_rates = {0.5f, 0.9f, 0.99f};
      d.CommitDeviceData();
      std::vector<float> v = Ramp(200, 0.1f);
      d.Run(200, v.data());
      Outputs r;
      Append(r, v);
      return r;
    }));
#endif

#if __has_include("BoxBlur_CPU.h")
Register boxBlur(MakeCase<BoxBlur>(
    "#include \"Image2d.h\" (the paper's spelling) and an Image2D member", "box_blur.h/.cpp", 1e-6, CONFORMANCE_MAKERS(BoxBlur, 29, 17),
    [](BoxBlur& b) {
      b.CommitDeviceData();
      std::vector<LiteMath::float4> out(29 * 17);
      b.Blur(29, 17, out.data());
      Outputs r;
      for (auto& p : out) Append(r, std::vector<float>{p.x, p.y, p.z, p.w});
      return r;
    }));
#endif

}  // namespace
