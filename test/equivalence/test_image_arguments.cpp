// Image2D parameters: ImageArguments, ImageArguments_CPU and ImageArguments_Vulkan, given the same
// images per call, give the same texels. The Vulkan class copies each image parameter to a device
// image for the call (and back unless it is const), binds it to the kernels it is passed to with
// its size in push constants, and binds members passed to kernels' image parameters likewise.
#include "ImageArguments.h"
#include "ImageArguments_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "ImageArguments_ISPC.h"
#endif
#include "ImageArguments_Vulkan.h"
#include "ImageSupport.h"
#include "TestSupport.h"

#include <cmath>

using LiteImage::Image2D;
using LiteImage::Sampler;
using LiteMath::float2;
using LiteMath::float4;

namespace
{
using Impls = std::vector<std::pair<const char*, std::shared_ptr<ImageArguments>>>;

Impls AllBackends(const std::shared_ptr<crossrt::VulkanContext>& ctx)
{
  Impls impls = {{"original", std::make_shared<ImageArguments>()}, {"CPU", CreateImageArguments_CPU()}};
#ifdef CROSSRT_HAS_ISPC
  impls.push_back({"ISPC", CreateImageArguments_ISPC()});  // the texels in place, sampled as LiteImage samples
#endif
  if (ctx) impls.push_back({"Vulkan", CreateImageArguments_Vulkan(ctx)});
  return impls;
}

// The blur of `in` as the test computes it: gain * the clamped 3x3 mean.
float4 ExpectedBlur(const Image2D<float4>& in, int x, int y, float gain)
{
  float4 sum(0.0f);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      sum += in.at(std::clamp(x + dx, 0, int(in.width()) - 1), std::clamp(y + dy, 0, int(in.height()) - 1));
  return sum * (gain / 9.0f);
}
}  // namespace

TEST_CASE("Image2D parameters: read, written and sized by kernels, at any size, empty included", "[equivalence][images]")
{
  auto ctx = ValidatedContext();
  for (auto& [name, impl] : AllBackends(ctx))
  {
    INFO(name);
    // Sizes that are not multiples of the group size, and one size after another: the device
    // image follows each call's argument.
    for (auto [w, h] : {std::pair<uint32_t, uint32_t>{37, 23}, {5, 61}, {1, 1}})
    {
      INFO(w << " x " << h);
      const Image2D<float4> in = RandomImage(w, h, 11 + w);
      Image2D<float4> out(w, h, float4(-7.0f));
      impl->Blur(in, out, 1.5f);
      REQUIRE(out.width() == w);
      REQUIRE(out.height() == h);
      float worst = 0.0f;
      for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x)
          if (const float d = MaxDifference(out.at(x, y), ExpectedBlur(in, int(x), int(y), 1.5f)); std::isnan(d) || d > worst) worst = d;
      REQUIRE(worst <= 1e-6f);
    }
    // Empty images: no thread runs and nothing is copied; the output stays empty.
    Image2D<float4> none, noneOut;
    impl->Blur(none, noneOut, 1.0f);
    REQUIRE(noneOut.width() == 0);
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Image2D parameters in place: a thread function scales the texels of an image it is given", "[equivalence][images]")
{
  auto ctx = ValidatedContext();
  const auto v = RandomFloats(19 * 13, 5, -3.0f, 3.0f);
  for (auto& [name, impl] : AllBackends(ctx))
  {
    INFO(name);
    Image2D<float> img(19, 13, v.data());
    impl->Scale(img, -2.5f);
    impl->Scale(img, 0.5f);
    for (uint32_t i = 0; i < 19 * 13; ++i)
    {
      INFO("texel " << i);
      REQUIRE(img.data()[i] == v[i] * -2.5f * 0.5f);  // exact: two float products in the same order
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Image2D members given to kernels' image parameters are written back, parameters read beside them", "[equivalence][images]")
{
  auto ctx = ValidatedContext();
  const uint32_t w = 29, h = 17;
  const Image2D<float4> frame0 = RandomImage(w, h, 21), frame1 = RandomImage(w, h, 22);
  const Image2D<float4> history0 = RandomImage(w, h, 20);
  ImageArguments reference;
  reference.m_history = history0;
  Image2D<uint32_t> labels0(w, h, 9u);
  reference.Accumulate(frame0, 0.25f, 0.5f, labels0);
  reference.Accumulate(frame1, 0.75f, 0.5f, labels0);
  // The original against the formula, so that an empty or unchanged result cannot pass.
  for (uint32_t i = 0; i < w * h; ++i)
  {
    float4 expected = history0.data()[i] * 0.75f + frame0.data()[i] * 0.25f;
    expected = expected * 0.25f + frame1.data()[i] * 0.75f;
    REQUIRE(MaxDifference(reference.m_history.data()[i], expected) <= 1e-6f);
  }
  uint32_t above = 0;
  for (uint32_t i = 0; i < w * h; ++i) above += labels0.data()[i];
  REQUIRE(above > 0);
  REQUIRE(above < w * h);
  for (auto& [name, impl] : AllBackends(ctx))
  {
    INFO(name);
    impl->m_history = history0;
    Image2D<uint32_t> labels(w, h, 9u);
    impl->Accumulate(frame0, 0.25f, 0.5f, labels);
    impl->Accumulate(frame1, 0.75f, 0.5f, labels);
    for (uint32_t i = 0; i < w * h; ++i)
    {
      INFO("texel " << i);
      REQUIRE(MaxDifference(impl->m_history.data()[i], reference.m_history.data()[i]) <= 1e-6f);
      const float4 c = reference.m_history.data()[i];
      if (std::fabs(0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z - 0.5f) > 1e-5f) REQUIRE(labels.data()[i] == labels0.data()[i]);
    }
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Image2D parameters sampled with nearest and bilinear filtering, their size read in the kernel", "[equivalence][images]")
{
  auto ctx = ValidatedContext();
  const int n = 2001;
  const auto coords = RandomFloats(2 * n, 31, -1.5f, 2.5f);
  std::vector<float2> uv(n);
  for (int i = 0; i < n; ++i) uv[i] = float2(coords[2 * i], coords[2 * i + 1]);
  const auto values = RandomFloats(11 * 7, 32, -2.0f, 2.0f);
  const Image2D<float> field(11, 7, values.data());
  const Image2D<float4> albedo = RandomImage(6, 9, 33);
  auto configure = [](ImageArguments& a) {
    a.m_nearest.addressU = Sampler::AddressMode::MIRROR;
    a.m_nearest.addressV = Sampler::AddressMode::CLAMP;
    a.m_linear.addressU = a.m_linear.addressV = Sampler::AddressMode::WRAP;
    a.m_linear.filter = Sampler::Filter::LINEAR;
  };
  ImageArguments reference;
  configure(reference);
  std::vector<float> heights0(n);
  std::vector<float4> colors0(n);
  reference.Sample(field, albedo, n, uv.data(), heights0.data(), colors0.data());
  REQUIRE(colors0[0].x != 0.0f);
  for (auto& [name, impl] : AllBackends(ctx))
  {
    INFO(name);
    configure(*impl);
    std::vector<float> heights(n, -100.0f);
    std::vector<float4> colors(n, float4(-100.0f));
    impl->Sample(field, albedo, n, uv.data(), heights.data(), colors.data());
    float heightError = 0.0f;
    int edges = 0;
    for (int i = 0; i < n; ++i)
    {
      INFO("uv " << uv[i].x << ", " << uv[i].y);
      heightError = std::max(heightError, std::fabs(heights[i] - heights0[i]));
      const float tx = uv[i].x * 6.0f, ty = uv[i].y * 9.0f;
      if (std::fabs(tx - std::round(tx)) > 1e-3f && std::fabs(ty - std::round(ty)) > 1e-3f)
        REQUIRE(MaxDifference(colors[i], colors0[i]) == 0.0f);  // 54 * the same texel
      else
        ++edges;
    }
    // 8 bits of sub-texel precision on lavapipe: a weight off by 1/512 of a range of 4.
    CHECK(heightError <= 4.0f * 4.0f / 512.0f);
    REQUIRE(edges < n / 50);
  }
  RequireNoValidationMessages(ctx);
}
