// Cases about the patterns of the paper (3.8, 3.9) written as kernel_slicer's samples write them:
// sorting records, appending then processing what was appended, virtual materials.
#include "Conformance.h"

#include "LiteMath.h"

// A case compiles where this build translated its class (CONFORMANCE_CLASSES); main checks that all were.
#if __has_include("SortPairs_CPU.h")
#include "SortPairs_CPU.h"
#include "SortPairs_Vulkan.h"
#endif
#if __has_include("RedPixels_CPU.h")
#include "RedPixels_CPU.h"
#include "RedPixels_Vulkan.h"
#endif
#if __has_include("ShadedSpheres_CPU.h")
#include "ShadedSpheres_CPU.h"
#include "ShadedSpheres_Vulkan.h"
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

#if __has_include("ShadedSpheres_CPU.h")
Register shadedSpheres(MakeCase<ShadedSpheres>(
    "virtual calls through std::vector<std::shared_ptr<IMaterial>>", "shaded_spheres.h/.cpp", 1e-5, CONFORMANCE_MAKERS(ShadedSpheres),
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

}  // namespace
