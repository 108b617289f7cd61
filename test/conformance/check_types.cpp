// Cases about types and functions: helpers that live only in the .cpp, copysign, scans with an
// operator and an initial value, double on the CPU, kernels returning bool, local arrays of
// vectors, structs by value, data of a base class.
#include "Conformance.h"

#include "LiteMath.h"
#include <cmath>
#include <stdexcept>
#include <vector>

// A case compiles where this build translated its class (CONFORMANCE_CLASSES); main checks that all were.
#if __has_include("Activations_CPU.h")
#include "Activations_CPU.h"
#include "Activations_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Activations_ISPC.h"
#endif
#endif
#if __has_include("HashNoise_CPU.h")
#include "HashNoise_CPU.h"
#include "HashNoise_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "HashNoise_ISPC.h"
#endif
#endif
#if __has_include("Tonemap_CPU.h")
#include "Tonemap_CPU.h"
#include "Tonemap_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Tonemap_ISPC.h"
#endif
#endif
#if __has_include("SignFlip_CPU.h")
#include "SignFlip_CPU.h"
#include "SignFlip_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "SignFlip_ISPC.h"
#endif
#endif
#if __has_include("PrefixSums_CPU.h")
#include "PrefixSums_CPU.h"
#include "PrefixSums_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "PrefixSums_ISPC.h"
#endif
#endif
#if __has_include("DoubleSum_CPU.h")
#include "DoubleSum_CPU.h"
#ifdef CONFORMANCE_ISPC
#include "DoubleSum_ISPC.h"
#endif
#endif
#if __has_include("DoubleScale_CPU.h")
#include "DoubleScale_CPU.h"
#ifdef CONFORMANCE_ISPC
#include "DoubleScale_ISPC.h"
#endif
#endif
#if __has_include("BounceLoop_CPU.h")
#include "BounceLoop_CPU.h"
#include "BounceLoop_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "BounceLoop_ISPC.h"
#endif
#endif
#if __has_include("Smooth4_CPU.h")
#include "Smooth4_CPU.h"
#include "Smooth4_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Smooth4_ISPC.h"
#endif
#endif
#if __has_include("FillVariable_CPU.h")
#include "FillVariable_CPU.h"
#include "FillVariable_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "FillVariable_ISPC.h"
#endif
#endif
#if __has_include("DerivedBlend_CPU.h")
#include "DerivedBlend_CPU.h"
#include "DerivedBlend_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "DerivedBlend_ISPC.h"
#endif
#endif

#include <limits>

using namespace conformance;
using LiteMath::float2;
using LiteMath::float4;

namespace {

#if __has_include("Tonemap_CPU.h")
Register tonemap(MakeCase<Tonemap>(
    "helpers only in the .cpp: static, free, static member, constexpr", "tonemap.h/.cpp", 1e-5, CONFORMANCE_MAKERS(Tonemap),
    [](Tonemap& t) {
      const int w = 31, h = 19;
      std::vector<float4> hdr(w * h), ldr(w * h);
      for (int i = 0; i < w * h; i++) hdr[i] = float4(0.01f * float(i % 301), 0.02f * float(i % 97), 0.5f, 1.0f);
      t.Apply(w, h, hdr.data(), ldr.data());
      Outputs r;
      for (auto& p : ldr) Append(r, std::vector<float>{p.x, p.y, p.z, p.w});
      return r;
    }));
#endif

#if __has_include("SignFlip_CPU.h")
Register signFlip(MakeCase<SignFlip>(
    "std::copysign and copysignf (signed zeros, infinities)", "sign_flip.h/.cpp", 0.0, CONFORMANCE_MAKERS(SignFlip), [](SignFlip& s) {
      const float inf = std::numeric_limits<float>::infinity();
      std::vector<float> mag = {1.0f, -2.0f, 0.0f, -0.0f, inf, 3.5f, -inf, 7.0f};
      std::vector<float> sign = {-1.0f, 1.0f, -0.0f, 0.0f, -5.0f, -0.0f, 2.0f, inf};
      std::vector<float> out(mag.size());
      s.Run(int(mag.size()), mag.data(), sign.data(), out.data());
      Outputs r;
      for (float v : out) r.insert(r.end(), {double(v), double(std::signbit(v))});
      return r;
    }));
#endif

#if __has_include("PrefixSums_CPU.h")
Register prefixSums(MakeCase<PrefixSums>(
    "std::inclusive_scan(first, last, out, std::plus<int>(), init) and exclusive_scan", "prefix_sums.h/.cpp", 0.0, CONFORMANCE_MAKERS(PrefixSums),
    [](PrefixSums& p) {
      std::vector<int> data(777), exc(777), inc(777);
      for (int i = 0; i < 777; i++) data[i] = (i * 31) % 17 - 5;
      p.Scan(data.data(), 777, exc.data(), inc.data());
      Outputs r;
      Append(r, exc);
      Append(r, inc);
      return r;
    }));
#endif

#if __has_include("DoubleSum_CPU.h")
Register doubleSum([] {
  Case c = MakeCase<DoubleSum>("double in a kernel (the CPU backends have none of the GPU's limits)", "double_sum.h/.cpp", 1e-12,
                               [] { return std::make_shared<DoubleSum>(); }, [] { return CreateDoubleSum_CPU(); }, nullptr, CONFORMANCE_ISPC_MAKER(DoubleSum, ), [](DoubleSum& d) {
                                 std::vector<double> data(4001);
                                 for (int i = 0; i < 4001; i++) data[i] = 1e-3 * double(i % 37) - 0.01;
                                 d.Sum(data.data(), data.size());
                                 return Outputs{d.m_summ};
                               });
  c.className = "DoubleSum";
  c.vulkanRefusal = "is not supported in Vulkan kernels: many GPUs have no 64-bit floats";
  return c;
}());
#endif

#if __has_include("DoubleScale_CPU.h")
Register doubleScale([] {
  Case c = MakeCase<DoubleScale>("double members, vectors, arrays, helpers, buffers; 1.0 / 3.0; int + double", "double_scale.h/.cpp", 1e-15,
                                 [] { return std::make_shared<DoubleScale>(); }, [] { return CreateDoubleScale_CPU(); }, nullptr,
                                 CONFORMANCE_ISPC_MAKER(DoubleScale, ), [](DoubleScale& d) {
                                   const int n = 1000;
                                   std::vector<float> in(n);
                                   for (int i = 0; i < n; i++) in[i] = 0.37f * float(i % 91) - 11.0f;
                                   std::vector<double> out(n, 0.0);
                                   d.Scale(n, in.data(), out.data());
                                   return Outputs(out.begin(), out.end());
                                 });
  c.className = "DoubleScale";
  c.vulkanRefusal = "is not supported in Vulkan kernels: many GPUs have no 64-bit floats";
  return c;
}());
#endif

#if __has_include("BounceLoop_CPU.h")
Register bounceLoop(MakeCase<BounceLoop>(
    "a kernel returning bool that ends a thread's loop: if (!kernel_X(...)) break;", "bounce_loop.h/.cpp", 1e-6, CONFORMANCE_MAKERS(BounceLoop),
    [](BounceLoop& b) {
      const uint32_t n = 400;
      std::vector<float> energy(n);
      for (uint32_t i = 0; i < n; i++) energy[i] = 0.05f * float(i % 40);
      std::vector<float4> out(n);
      b.Trace(n, energy.data(), out.data());
      Outputs r;
      for (auto& p : out) Append(r, std::vector<float>{p.x, p.y});
      return r;
    }));
#endif

#if __has_include("Smooth4_CPU.h")
Register smooth4(MakeCase<Smooth4>(
    "a local array of vectors (float2 taps[4]) and an initialised float array", "smooth4.h/.cpp", 1e-5, CONFORMANCE_MAKERS(Smooth4),
    [](Smooth4& s) {
      std::vector<float2> in(100), out(100);
      for (int i = 0; i < 100; i++) in[i] = float2(float(i), float(100 - i));
      s.Run(100, in.data(), out.data());
      Outputs r;
      for (auto& p : out) Append(r, std::vector<float>{p.x, p.y});
      return r;
    }));
#endif

#if __has_include("FillVariable_CPU.h")
Register fillVariable(MakeCase<FillVariable>(
    "a struct passed by value to kernels, and a struct-making helper", "fill_variable.h/.cpp", 0.0, CONFORMANCE_MAKERS(FillVariable),
    [](FillVariable& f) {
      std::vector<float> data(100, -1.0f);
      std::vector<BoxHit> hits(60);
      f.Fill(data.data(), 100, hits.data(), 60);
      Outputs r;
      Append(r, data);
      for (auto& h : hits) r.insert(r.end(), {double(h.id), double(h.t)});
      return r;
    }));
#endif

#if __has_include("DerivedBlend_CPU.h")
Register derivedBlend(MakeCase<DerivedBlend>(
    "a derived class's kernel reading its base's data and vector; the control function in the base", "inherited_data.h/.cpp", 1e-6,
    CONFORMANCE_MAKERS(DerivedBlend), [](DerivedBlend& d) {
      d.Init();
      d.CommitDeviceData();
      std::vector<float> data(64, 0.0f);
      d.Test(data.data(), 64);
      Outputs r;
      Append(r, data);
      return r;
    }));
#endif

#if __has_include("HashNoise_CPU.h")
Register hashNoise(MakeCase<HashNoise>(
    "a struct's own state advanced by its method (rng.Next()), a structured binding, std::fmod/isnan/isfinite, {} zeros",
    "hash_noise.h/.cpp", 1e-5, CONFORMANCE_MAKERS(HashNoise), [](HashNoise& h) {
      std::vector<float> out(37 * 23);
      h.CommitDeviceData();
      h.Run(37, 23, out.data());
      Outputs r;
      Append(r, out);
      return r;
    }));
#endif

#if __has_include("Activations_CPU.h")
// The GPU's and ISPC's hyperbolic functions are not C++'s to the last bit: to 1e-4.
Register activations(MakeCase<Activations>(
    "tanh, sinh, cosh, asinh, acosh, atanh (std:: and C's f names) in a kernel", "activations.h/.cpp", 1e-4, CONFORMANCE_MAKERS(Activations),
    [](Activations& a) {
      a.CommitDeviceData();
      std::vector<float> in;
      for (float x : {0.0f, -0.0f, 1e-6f, -3e-3f, 0.02f, 0.5f, -0.75f, 1.0f, 2.5f, -4.0f, 9.0f, -20.0f}) in.push_back(x);
      std::vector<float> out(6 * in.size());
      a.Apply(in.data(), out.data(), int(in.size()));
      if (std::abs(out[6 * 7] - 0.7615942f) > 1e-5f) throw std::runtime_error("tanh(1) should be 0.7615942");
      Outputs r;
      Append(r, out);
      return r;
    }));
#endif

}  // namespace
