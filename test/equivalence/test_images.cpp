// Textures: the original ImageFilters, ImageFilters_CPU and ImageFilters_Vulkan (storage images,
// textures and samplers on the GPU) give the same texels. Loads and stores are exact up to float
// rounding; nearest samples are exact away from texel edges; bilinear samples differ by the
// GPU's sub-texel precision (Vulkan requires at least 4 bits; lavapipe has 8).
#include "ImageFilters.h"
#include "ImageFilters_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "ImageFilters_ISPC.h"
#endif
#include "ImageFilters_Vulkan.h"
#include "ImageSupport.h"
#include "TestSupport.h"

#include <cmath>

using LiteImage::Image2D;
using LiteImage::Sampler;
using LiteMath::float2;
using LiteMath::float4;

namespace
{
void Fill(ImageFilters& f, uint32_t w, uint32_t h)
{
  f.m_source = RandomImage(w, h, 7);
  const auto heights = RandomFloats(int(19 * 11), 8, -2.0f, 2.0f);
  f.m_heights = Image2D<float>(19, 11, heights.data());
  f.m_blurred = Image2D<float4>(w, h);
  f.m_luminance = Image2D<float>(w, h);
  f.m_labels = Image2D<uint32_t>(w, h, 7u);
  f.m_accumulated = Image2D<float4>(w, h, float4(0.25f));
  f.m_counts = Image2D<uint32_t>(w, h, 3u);
}

using Impls = std::vector<std::pair<const char*, std::shared_ptr<ImageFilters>>>;

Impls AllBackends(const std::shared_ptr<crossrt::VulkanContext>& ctx)
{
  Impls impls = {{"original", std::make_shared<ImageFilters>()}, {"CPU", CreateImageFilters_CPU()}};
#ifdef CROSSRT_HAS_ISPC
  impls.push_back({"ISPC", CreateImageFilters_ISPC()});  // the texels in place, sampled as LiteImage samples
#endif
  if (ctx) impls.push_back({"Vulkan", CreateImageFilters_Vulkan(ctx)});
  return impls;
}

// Distance of a coordinate from the nearest texel edge, in texels: nearest sampling may pick
// either side within the GPU's precision there.
float EdgeDistance(float u, uint32_t size)
{
  const float t = u * float(size);
  return std::fabs(t - std::round(t));
}
}  // namespace

TEST_CASE("Image2D members: texels loaded and stored by kernels, in helpers and thread functions too", "[equivalence][images]")
{
  auto ctx = ValidatedContext();
  const uint32_t w = 37, h = 23;  // not powers of two, not multiples of the group size
  ImageFilters reference;
  Fill(reference, w, h);
  reference.Blur(0.5f);
  reference.Accumulate(0.5f);
  reference.Accumulate(2.0f);
  reference.Double();
  uint32_t above = 0;
  for (uint32_t i = 0; i < w * h; ++i) above += reference.m_labels.data()[i];
  REQUIRE(above > 0);  // the threshold splits the image
  REQUIRE(above < w * h);
  for (auto& [name, impl] : AllBackends(ctx))
  {
    INFO(name);
    Fill(*impl, w, h);
    impl->Blur(0.5f);
    impl->Accumulate(0.5f);
    impl->Accumulate(2.0f);
    impl->Double();
    REQUIRE(impl->m_blurred.width() == w);
    for (uint32_t i = 0; i < w * h; ++i)
    {
      INFO("texel " << i);
      REQUIRE(MaxDifference(impl->m_blurred.data()[i], reference.m_blurred.data()[i]) <= 1e-6f);
      REQUIRE(std::fabs(impl->m_luminance.data()[i] - reference.m_luminance.data()[i]) <= 1e-6f);
      if (std::fabs(reference.m_luminance.data()[i] - 0.5f) > 1e-5f) REQUIRE(impl->m_labels.data()[i] == reference.m_labels.data()[i]);
      REQUIRE(MaxDifference(impl->m_accumulated.data()[i], reference.m_accumulated.data()[i]) <= 1e-6f);
      REQUIRE(impl->m_counts.data()[i] == 5u);
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Image2D members sampled with nearest and bilinear filtering in every address mode", "[equivalence][images]")
{
  auto ctx = ValidatedContext();
  const int n = 3001;
  const auto coords = RandomFloats(2 * n, 3, -1.5f, 2.5f);  // outside [0, 1] too: address modes matter
  std::vector<float2> uv(n);
  for (int i = 0; i < n; ++i) uv[i] = float2(coords[2 * i], coords[2 * i + 1]);
  using Mode = Sampler::AddressMode;
  for (Mode mode : {Mode::WRAP, Mode::MIRROR, Mode::CLAMP, Mode::BORDER, Mode::MIRROR_ONCE})
  {
    DYNAMIC_SECTION("address mode " << int(mode))
    {
      auto configure = [&](ImageFilters& f) {
        Fill(f, 13, 7);
        f.m_nearest.addressU = f.m_nearest.addressV = mode;
        f.m_linear = f.m_nearest;
        f.m_linear.filter = Sampler::Filter::LINEAR;
        f.m_linear.borderColor = float4(0.0f, 0.0f, 0.0f, 1.0f);
        f.m_heightSampler = f.m_linear;
        f.m_heightSampler.addressU = Mode::CLAMP;  // U and V may differ
        f.m_heightSampler.borderColor = float4(1.0f);
      };
      ImageFilters reference;
      configure(reference);
      std::vector<float4> nearest0(n), linear0(n);
      std::vector<float> heights0(n);
      reference.Sample(n, uv.data(), nearest0.data(), linear0.data(), heights0.data());
      for (auto& [name, impl] : AllBackends(ctx))
      {
        INFO(name);
        configure(*impl);
        std::vector<float4> nearest(n), linear(n);
        std::vector<float> heights(n);
        impl->Sample(n, uv.data(), nearest.data(), linear.data(), heights.data());
        float linearError = 0.0f, heightError = 0.0f;
        int edges = 0;
        for (int i = 0; i < n; ++i)
        {
          INFO("uv " << uv[i].x << ", " << uv[i].y);
          if (EdgeDistance(uv[i].x, 13) > 1e-3f && EdgeDistance(uv[i].y, 7) > 1e-3f)
            REQUIRE(MaxDifference(nearest[i], nearest0[i]) == 0.0f);
          else
            ++edges;
          linearError = std::max(linearError, MaxDifference(linear[i], linear0[i]));
          heightError = std::max(heightError, std::fabs(heights[i] - heights0[i]));
        }
        // 8 bits of sub-texel precision: a weight is off by at most 1/512 of the texel range
        // (1 for the source, 4 for the heights).
        CHECK(linearError <= 4.0f / 512.0f);
        CHECK(heightError <= 4.0f * 4.0f / 512.0f);
        REQUIRE(edges < n / 50);
      }
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Image2D members: changes reach the GPU", "[equivalence][images]")
{
  auto ctx = ValidatedContext();
  if (!ctx) return;
  auto gpu = CreateImageFilters_Vulkan(ctx);
  ImageFilters cpu;
  for (ImageFilters* f : {gpu.get(), &cpu}) Fill(*f, 16, 16);
  auto same = [&] {
    for (ImageFilters* f : {gpu.get(), &cpu}) f->Blur(0.5f);
    for (uint32_t i = 0; i < cpu.m_blurred.width() * cpu.m_blurred.height(); ++i)
      if (MaxDifference(gpu->m_blurred.data()[i], cpu.m_blurred.data()[i]) > 1e-6f) return false;
    return gpu->m_blurred.width() == cpu.m_blurred.width();
  };
  REQUIRE(same());
  // Texels changed in place: seen after CommitDeviceData().
  for (ImageFilters* f : {gpu.get(), &cpu}) f->m_source.set(3, 4, float4(10.0f));
  gpu->CommitDeviceData();
  REQUIRE(same());
  // A new size is noticed by itself.
  for (ImageFilters* f : {gpu.get(), &cpu}) Fill(*f, 40, 9);
  REQUIRE(same());
  // So is a changed sampler.
  const int n = 257;
  const auto coords = RandomFloats(2 * n, 9, -0.5f, 1.5f);
  std::vector<float2> uv(n);
  for (int i = 0; i < n; ++i) uv[i] = float2(coords[2 * i], coords[2 * i + 1]);
  std::vector<float4> a(n), b(n), la(n), lb(n);
  std::vector<float> ha(n), hb(n);
  for (ImageFilters* f : {gpu.get(), &cpu}) f->m_nearest.addressU = f->m_nearest.addressV = Sampler::AddressMode::CLAMP;
  gpu->Sample(n, uv.data(), a.data(), la.data(), ha.data());
  cpu.Sample(n, uv.data(), b.data(), lb.data(), hb.data());
  int differ = 0;
  for (int i = 0; i < n; ++i) differ += MaxDifference(a[i], b[i]) > 0.0f;
  REQUIRE(differ <= 2);  // at most a texel-edge coordinate or two
  RequireNoValidationMessages(ctx);
}

TEST_CASE("A sampler's border colour must be one Vulkan has", "[equivalence][images]")
{
  auto ctx = ValidatedContext();
  if (!ctx) return;
  auto gpu = CreateImageFilters_Vulkan(ctx);
  Fill(*gpu, 4, 4);
  gpu->m_linear.addressU = Sampler::AddressMode::BORDER;
  gpu->m_linear.borderColor = float4(0.5f, 0.25f, 0.0f, 1.0f);
  std::vector<float2> uv(1, float2(0.5f));
  std::vector<float4> a(1), b(1);
  std::vector<float> c(1);
  REQUIRE_THROWS_WITH(gpu->Sample(1, uv.data(), a.data(), b.data(), c.data()),
                      Catch::Contains("ImageFilters::m_linear") && Catch::Contains("border colour") && Catch::Contains("(1,1,1,1)"));
  RequireNoValidationMessages(ctx);
}
