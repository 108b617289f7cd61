// Members declared CRT_SPECIALIZE (Specialize.h) are constants of the GPU's pipelines: the _Vulkan
// class makes its pipelines for the values they hold, and makes them again when one changes between
// calls, with no CommitDeviceData() from the user. Every backend maps as the class as written does,
// for every curve, banding, white point and clamping, changed call after call; the _Vulkan class's
// pipelines hold the members' values (crt_pipelineConstants).
#include "tone_curves.h"
#include "ToneMapper_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "ToneMapper_ISPC.h"
#endif
#include "ToneMapper_Vulkan.h"
#include "TestSupport.h"

#include <cmath>
#include <cstring>
#include <random>

using namespace LiteMath;

namespace {

// The generated class as a user subclasses it: the specialization its pipelines were made with.
class InspectedToneMapper : public ToneMapper_Vulkan
{
public:
  using ToneMapper_Vulkan::ToneMapper_Vulkan;
  std::vector<uint32_t> PipelineConstants() const { return crt_pipelineConstants; }
};

uint32_t Bits(float f)
{
  uint32_t b = 0;
  std::memcpy(&b, &f, sizeof(b));
  return b;
}

}  // namespace

TEST_CASE("CRT_SPECIALIZE members: every backend maps as the original, settings changed between calls", "[equivalence][specialize]")
{
  auto ctx = ValidatedContext();
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> value(-0.5f, 12.0f);
  std::vector<float4> hdr(2053);
  for (float4& c : hdr) c = float4(value(rng), value(rng), value(rng), 0.5f);

  struct Settings
  {
    ToneCurve curve;
    float whitePoint;
    int bands;
    bool clampNegative;
    float exposure;
  };
  const Settings settings[] = {
      {ToneCurve::Aces, 4.0f, 0, true, 1.0f},     {ToneCurve::Linear, 3.0f, 0, true, 0.5f}, {ToneCurve::Reinhard, 6.0f, 0, true, 1.0f},
      {ToneCurve::Reinhard, 6.0f, 8, true, 1.0f}, {ToneCurve::Aces, 2.0f, 5, false, 0.5f},   {ToneCurve::Linear, 9.0f, 3, false, 2.0f},
      {ToneCurve::Aces, 4.0f, 0, true, 1.5f},  // back to the first pipelines' settings, with another exposure
  };
  auto original = std::make_shared<ToneMapper>();
  std::vector<std::pair<const char*, std::shared_ptr<ToneMapper>>> impls = {{"CPU", CreateToneMapper_CPU()}};
#ifdef CROSSRT_HAS_ISPC
  impls.push_back({"ISPC", CreateToneMapper_ISPC()});
#endif
  std::shared_ptr<InspectedToneMapper> vulkan;
  if (ctx)
  {
    vulkan = std::make_shared<InspectedToneMapper>(ctx);
    impls.push_back({"Vulkan", vulkan});
  }
  for (auto& [name, impl] : impls) impl->CommitDeviceData();  // once: the calls below notice every change themselves
  for (const Settings& s : settings)
  {
    INFO("curve " << int(s.curve) << ", white point " << s.whitePoint << ", " << s.bands << " bands, clamp " << s.clampNegative
                  << ", exposure " << s.exposure);
    std::vector<float4> expected(hdr.size());
    original->m_curve = s.curve, original->m_whitePoint = s.whitePoint, original->m_bands = s.bands;
    original->m_clampNegative = s.clampNegative, original->m_exposure = s.exposure;
    original->Map(int(hdr.size()), hdr.data(), expected.data());
    REQUIRE(original->m_clipped > 0);
    REQUIRE(original->m_clipped < hdr.size());
    for (auto& [name, impl] : impls)
    {
      INFO(name);
      impl->m_curve = s.curve, impl->m_whitePoint = s.whitePoint, impl->m_bands = s.bands, impl->m_clampNegative = s.clampNegative;
      impl->m_exposure = s.exposure;
      std::vector<float4> ldr(hdr.size(), float4(-1.0f));
      impl->Map(int(hdr.size()), hdr.data(), ldr.data());
      // Within float rounding (a GPU divides within 2.5 ulp); with bands, a value on a band's edge
      // may fall into the next band: at most one band, for few values.
      size_t far = 0, nextBand = 0;
      for (size_t i = 0; i < hdr.size(); ++i)
        for (int c = 0; c < 4; ++c)
        {
          const float d = std::fabs(ldr[i][c] - expected[i][c]);
          if (d <= 1e-5f) continue;
          if (s.bands > 0 && d <= 1.0f / float(s.bands) + 1e-5f) ++nextBand;
          else ++far;
        }
      REQUIRE(far == 0);
      REQUIRE(nextBand <= hdr.size() / 200);
      REQUIRE(impl->m_clipped == original->m_clipped);
      REQUIRE(impl->m_clippedShare == original->m_clippedShare);
    }
    if (vulkan)  // its pipelines were made for these values: the curve, white point, bands, clamp
      REQUIRE(vulkan->PipelineConstants() ==
              std::vector<uint32_t>{uint32_t(s.curve), Bits(s.whitePoint), uint32_t(s.bands), s.clampNegative ? 1u : 0u});
  }
  RequireNoValidationMessages(ctx);
}
