// Cases about the patterns of the paper (3.8, 3.9) written as kernel_slicer's samples write them:
// sorting records, appending then processing what was appended, virtual materials.
#include "Conformance.h"

#include "LiteMath.h"
#include <algorithm>
#include <cmath>
#include <stdexcept>

// A case compiles where this build translated its class (CONFORMANCE_CLASSES); main checks that all were.
#if __has_include("SortPairs_CPU.h")
#include "SortPairs_CPU.h"
#include "SortPairs_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "SortPairs_ISPC.h"
#endif
#endif
#if __has_include("Lookalikes_CPU.h")
#include "Lookalikes_CPU.h"
#include "Lookalikes_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Lookalikes_ISPC.h"
#endif
#endif
#if __has_include("RedPixels_CPU.h")
#include "RedPixels_CPU.h"
#include "RedPixels_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "RedPixels_ISPC.h"
#endif
#endif
#if __has_include("ShadedSpheres_CPU.h")
#include "ShadedSpheres_CPU.h"
#include "ShadedSpheres_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "ShadedSpheres_ISPC.h"
#endif
#endif
#if __has_include("PointerHits_CPU.h")
#include "PointerHits_CPU.h"
#include "PointerHits_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "PointerHits_ISPC.h"
#endif
#endif
#if __has_include("StagedSaxpy_CPU.h")
#include "StagedSaxpy_CPU.h"
#include "StagedSaxpy_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "StagedSaxpy_ISPC.h"
#endif
#endif
#if __has_include("FractalView_CPU.h")
#include "FractalView_CPU.h"
#include "FractalView_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "FractalView_ISPC.h"
#endif
#endif
#if __has_include("LambdaMix_CPU.h")
#include "LambdaMix_CPU.h"
#include "LambdaMix_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "LambdaMix_ISPC.h"
#endif
#endif
#if __has_include("MovingBoxes_CPU.h")
#include "MovingBoxes_CPU.h"
#include "MovingBoxes_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "MovingBoxes_ISPC.h"
#endif
#endif

using namespace conformance;
using LiteMath::float4;

namespace {

#if __has_include("SortPairs_CPU.h")
Register sortPairs(MakeCase<SortPairs>(
    "std::sort of a member vector with a lambda on one field", "sort_pairs.h/.cpp", 0.0, CONFORMANCE_MAKERS(SortPairs), [](SortPairs& s) {
      s.CommitDeviceData();
      std::vector<LiteMath::uint2> out(1000);
      s.MakeAndSort(12345u, out.data());
      Outputs r;
      for (auto& p : out) r.insert(r.end(), {double(p.x), double(p.y)});
      return r;
    }));
#endif

#if __has_include("RedPixels_CPU.h")
Register redPixels(MakeCase<RedPixels>(
    "push_back in a kernel, then a kernel over m_found.size() (indirect)", "red_pixels.h/.cpp", 0.0, CONFORMANCE_MAKERS(RedPixels),
    [](RedPixels& p) {
      std::vector<uint32_t> image(4096);
      for (uint32_t i = 0; i < 4096; i++) image[i] = (i % 5 == 0) ? 0x002010F0u : 0x00808080u + i;
      p.CommitDeviceData();
      p.ProcessPixels(image.data(), uint32_t(image.size()));
      Outputs r;
      Append(r, image);
      r.push_back(double(p.m_found.size()));
      r.push_back(double(p.m_redPixelsNum));
      return r;
    }));
#endif

#if __has_include("PointerHits_CPU.h")
Register pointerHits(MakeCase<PointerHits>(
    "virtual methods that report through a pointer, Intersect(..., &hit) over a std::vector of shapes", "pointer_hits.h/.cpp", 1e-5,
    CONFORMANCE_MAKERS(PointerHits), [](PointerHits& p) {
      p.CommitDeviceData();
      const uint32_t n = 400;
      std::vector<float4> dirs(n), out(n);
      for (uint32_t i = 0; i < n; i++) dirs[i] = float4(-0.5f + float(i % 20) / 19.0f, -0.45f + float(i / 20) / 25.0f, 1.0f, 0.0f);
      p.Trace(n, dirs.data(), out.data());
      Outputs r;
      for (const float4& o : out) Append(r, std::vector<float>{o.x, o.y, o.z});
      return r;
    }));
#endif

#if __has_include("ShadedSpheres_CPU.h")
Register shadedSpheres(MakeCase<ShadedSpheres>(
    "virtual calls through std::vector<std::shared_ptr<IMaterial>>, an element or a local pointer to it", "shaded_spheres.h/.cpp", 1e-5, CONFORMANCE_MAKERS(ShadedSpheres),
    [](ShadedSpheres& s) {
      s.CommitDeviceData();
      std::vector<float4> normals(300), out(300);
      for (int i = 0; i < 300; i++) normals[i] = float4(std::sin(0.1f * float(i)), std::cos(0.07f * float(i)), 1.0f, float(i % 3));
      s.Shade(300, normals.data(), out.data());
      Outputs r;
      for (auto& p : out) Append(r, std::vector<float>{p.x, p.y, p.z, p.w});
      return r;
    }));
#endif

#if __has_include("FractalView_CPU.h")
// GPU transcendentals (pow, acos, atan2 in the Mandelbulb) round differently: hits agree, and the
// depths to within 1e-3 of the mean.
Register fractalView(MakeCase<FractalView>(
    "a library's virtual hierarchy (litesdf::ISdf: namespaced, private data), a reduction finished after the kernel", "analytic_sdf.h/.cpp", 1e-3,
    CONFORMANCE_MAKERS(FractalView, 64, 48), [](FractalView& v) {
      v.Add(std::make_shared<litesdf::SdfMandelbulb>(LiteMath::float3(0.0f, 0.0f, 0.0f), 0.9f, 8.0f, 8));
      v.Add(std::make_shared<litesdf::SdfRoundedBox>(LiteMath::float3(0.0f, -1.3f, 0.0f), LiteMath::float3(2.0f, 0.2f, 2.0f), 0.05f));
      v.Add(std::make_shared<litesdf::SdfTorus>(LiteMath::float3(1.4f, 0.0f, -0.5f), 0.4f, 0.12f));
      v.Add(std::make_shared<litesdf::SdfSphere>(LiteMath::float3(-1.4f, 0.0f, -0.3f), 0.35f));
      v.Add(std::make_shared<litesdf::SdfBox>(LiteMath::float3(-1.0f, 0.8f, -1.0f), LiteMath::float3(0.2f, 0.3f, 0.2f)));
      v.CommitDeviceData();
      std::vector<float> depth(64 * 48);
      v.Render(depth.data());
      Outputs r{v.Coverage()};
      double sum = 0.0, hits = 0.0;
      for (float t : depth) {
        r.push_back(t >= 0.0f ? 1.0 : 0.0);
        if (t >= 0.0f) sum += t, hits += 1.0;
      }
      r.push_back(sum / std::max(hits, 1.0));
      return r;
    }));
#endif

#if __has_include("LambdaMix_CPU.h")
Register lambdaMix(MakeCase<LambdaMix>(
    "lambdas (no capture, [k], [&sum], [this], called in place); for (x : range) over arrays and a member std::vector", "lambdas.h/.cpp", 1e-5,
    CONFORMANCE_MAKERS(LambdaMix), [](LambdaMix& m) {
      m.CommitDeviceData();
      std::vector<float> in(333), out(333);
      for (size_t i = 0; i < in.size(); i++) in[i] = std::sin(0.05f * float(i));
      m.Mix(uint32_t(in.size()), in.data(), out.data());
      Outputs r;
      Append(r, out);
      return r;
    }));
#endif

#if __has_include("MovingBoxes_CPU.h")
Register movingBoxes(MakeCase<MovingBoxes>(
    "ISceneObject with AABB geometry and a motion instance, RayQuery_NearestHitMotion", "moving_boxes.h/.cpp", 1e-5,
    CONFORMANCE_MAKERS(MovingBoxes), [](MovingBoxes& m) {
      m.CommitDeviceData();
      // Rays straight down across the row of boxes and the quad's path, and a few sideways.
      std::vector<float4> org, dir;
      for (int i = 0; i < 96; i++) {
        org.push_back(float4(-0.5f + 0.1f * float(i), 0.5f, 10.0f, 0.0f));
        dir.push_back(float4(0.0f, 0.0f, -1.0f, 100.0f));
      }
      for (int i = 0; i < 8; i++) {
        org.push_back(float4(-5.0f, 0.25f + 0.05f * float(i), 3.0f + 0.1f * float(i), 0.0f));
        dir.push_back(float4(1.0f, 0.0f, 0.0f, 100.0f));
      }
      const uint32_t n = uint32_t(org.size());
      Outputs r;
      for (float time : {0.0f, 0.3f, 0.5f, 0.8f, 1.0f}) {
        std::vector<int> what(n);
        std::vector<float> dist(n);
        m.Trace(n, org.data(), dir.data(), what.data(), dist.data(), time);
        // Known answers, so that agreeing on nothing cannot pass: the first box (primitive 0, at z
        // in [3, 4] once placed) straight down from z = 10, and the quad alone at x = 8.3 at time 1.
        if (time == 0.0f && (what[10] != 1000 || std::abs(dist[10] - 6.0f) > 1e-4f))
          throw std::runtime_error("ray 10 at time 0 should enter box primitive 0 at t = 6");
        if (time == 1.0f && (what[88] < 0 || what[88] >= 1000 || std::abs(dist[88] - 11.0f) > 1e-4f))
          throw std::runtime_error("ray 88 at time 1 should hit the quad at t = 11");
        Append(r, what);
        Append(r, dist);
      }
      return r;
    }));
#endif

#if __has_include("Lookalikes_CPU.h")
Register lookalikes(MakeCase<Lookalikes>(
    "user names equal to names the generated code derived (m_a_size beside m_a, m_img_width beside m_img, a parameter srcBuffer beside src, a struct LookalikesData, m_totalLocal and m_totalShared beside a reduction of m_total)",
    "user_names.h/.cpp", 1e-6, CONFORMANCE_MAKERS(Lookalikes, 40), [](Lookalikes& l) {
      l.CommitDeviceData();
      std::vector<float> src(100), out(100, -1.0f);
      for (size_t i = 0; i < src.size(); i++) src[i] = 0.125f * float(i);
      l.Run(int(src.size()), src.data(), out.data());
      // a known answer: 7 (m_a_size) + 4.5 (m_a_capacity / 2) + 40 (m_a.size()) + 0.25 (bias) + 4 (m_img.width())
      // + 3 (m_img_width) + 62 (m_totalLocal ... m_totalSubgroup) = 120.75, and a texel, 0.5 * (i % 4)
      for (size_t i = 0; i < out.size(); i++)
        if (out[i] != src[i] + float(i % 40 % 5) + 120.75f + 0.5f * float(i % 4)) throw std::runtime_error("srcBuffer[" + std::to_string(i) + "] is " + std::to_string(out[i]));
      Outputs r;
      Append(r, out);
      r.push_back(l.m_total);
      return r;
    }));
#endif

#if __has_include("StagedSaxpy_CPU.h")
Register stagedSaxpy(MakeCase<StagedSaxpy>(
    "std::vector locals of a control function between its kernels: (n), (n, value), data() + offset, size()", "staged_saxpy.h/.cpp", 0.0,
    CONFORMANCE_MAKERS(StagedSaxpy), [](StagedSaxpy& s) {
      s.CommitDeviceData();
      Outputs r;
      for (uint32_t n : {1000u, 4u}) {  // offsets of n floats: the device binds at multiples of 16 bytes
        std::vector<float> x(n), y(n), out(n, -1.0f);
        for (uint32_t i = 0; i < n; i++) {
          x[i] = float(i % 17);
          y[i] = 0.5f * float(i % 5);
        }
        s.Run(x.data(), y.data(), out.data(), n);
        for (uint32_t i = 0; i < n; i++)  // a known answer: agreeing on garbage cannot pass
          if (out[i] != x[i] * y[i] + 2.0f) throw std::runtime_error("out[" + std::to_string(i) + "] should be x * y + 2");
        Append(r, out);
      }
      return r;
    }));
#endif

}  // namespace
