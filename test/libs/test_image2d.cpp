// Tests for LiteImage::Image2D: container, sampler address modes/filters and OIIO round trips.
#include <catch2/catch.hpp>

#include "Image2D.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

using namespace LiteMath;
using namespace LiteImage;

namespace
{
// A unique path in the temp directory; the file is removed when the object dies.
struct TempFile
{
  std::string path;
  explicit TempFile(const std::string& ext)
  {
    std::random_device rd;
    path = (std::filesystem::temp_directory_path() /
            ("crossrt_image_test_" + std::to_string(rd()) + "_" + std::to_string(rd()) + "." + ext))
               .string();
  }
  ~TempFile() { std::remove(path.c_str()); }
};

Image2D<float4> makeTestImage(uint32_t w, uint32_t h)
{
  Image2D<float4> img(w, h);
  for (uint32_t y = 0; y < h; y++)
    for (uint32_t x = 0; x < w; x++)
      img.set(int(x), int(y), float4(float(x) / float(w), float(y) / float(h), 0.25f + 0.01f * float(x + y), 1.0f - 0.1f * float(x)));
  return img;
}

Sampler makeSampler(Sampler::AddressMode mode, Sampler::Filter filter)
{
  Sampler s;
  s.addressU = s.addressV = mode;
  s.filter                = filter;
  s.borderColor           = float4(-1.0f, -2.0f, -3.0f, -4.0f);
  return s;
}
} // namespace

TEST_CASE("Image2D container basics", "[liteimage]")
{
  Image2D<float> empty;
  CHECK(empty.width() == 0);
  CHECK(empty.height() == 0);

  const float     src[6] = {1, 2, 3, 4, 5, 6};
  Image2D<float> img(3, 2, src);
  CHECK(img.width() == 3);
  CHECK(img.height() == 2);
  CHECK(img.at(2, 0) == 3.0f);
  CHECK(img.at(0, 1) == 4.0f); // row-major, row 0 first
  CHECK(img[int2(1, 1)] == 5.0f);
  img.set(1, 1, 50.0f);
  CHECK(img.data()[4] == 50.0f);
  CHECK(img.vector().size() == 6);

  Image2D<uint32_t> filled(4, 4, 0xAABBCCDDu);
  CHECK(filled.at(3, 3) == 0xAABBCCDDu);
  filled.resize(2, 5);
  CHECK(filled.vector().size() == 10);
  CHECK(filled.at(1, 4) == 0u);
  filled.clear();
  CHECK((filled.width() == 0 && filled.vector().empty()));
}

TEST_CASE("Image2D bilinear sampling", "[liteimage]")
{
  const float    src[4] = {0.0f, 1.0f, 2.0f, 3.0f}; // 2x2
  Image2D<float> img(2, 2, src);
  const Sampler  lin = makeSampler(Sampler::AddressMode::CLAMP, Sampler::Filter::LINEAR);
  // Texel centers return the texels exactly.
  CHECK(img.sample(lin, float2(0.25f, 0.25f)) == Approx(0.0f));
  CHECK(img.sample(lin, float2(0.75f, 0.25f)) == Approx(1.0f));
  CHECK(img.sample(lin, float2(0.25f, 0.75f)) == Approx(2.0f));
  CHECK(img.sample(lin, float2(0.75f, 0.75f)) == Approx(3.0f));
  // Midpoint between two horizontal neighbours and the center of all four.
  CHECK(img.sample(lin, float2(0.5f, 0.25f)) == Approx(0.5f));
  CHECK(img.sample(lin, float2(0.5f, 0.5f)) == Approx(1.5f));
  // Quarter way: 0.75*t0 + 0.25*t1.
  CHECK(img.sample(lin, float2(0.375f, 0.25f)) == Approx(0.25f));

  const Image2D<float4> img4 = makeTestImage(4, 4);
  const float4          a = img4.at(1, 2), b = img4.at(2, 2);
  const float4          m = img4.sample(lin, float2(0.5f, 2.5f / 4.0f));
  for (int c = 0; c < 4; c++)
    CHECK(m[c] == Approx(0.5f * (a[c] + b[c])));
  const float4 center = img4.sample(lin, float2(1.5f / 4.0f, 2.5f / 4.0f));
  for (int c = 0; c < 4; c++)
    CHECK(center[c] == Approx(a[c]));
}

TEST_CASE("Image2D nearest sampling and address modes", "[liteimage]")
{
  const float    src[4] = {10.0f, 11.0f, 12.0f, 13.0f}; // 4x1
  Image2D<float> img(4, 1, src);
  using AM         = Sampler::AddressMode;
  const auto near  = [&](AM mode, float u) { return img.sample(makeSampler(mode, Sampler::Filter::NEAREST), float2(u, 0.5f)); };
  const auto lin   = [&](AM mode, float u) { return img.sample(makeSampler(mode, Sampler::Filter::LINEAR), float2(u, 0.5f)); };

  // Inside: texel i covers u in [i/4, (i+1)/4).
  CHECK(near(AM::CLAMP, 0.3f) == 11.0f);
  CHECK(near(AM::WRAP, 0.99f) == 13.0f);

  // u = 1.1 -> texel 4;  u = -0.1 -> texel -1;  u = 1.3 -> texel 5.
  CHECK(near(AM::WRAP, 1.1f) == 10.0f);
  CHECK(near(AM::WRAP, -0.1f) == 13.0f);
  CHECK(near(AM::WRAP, 1.3f) == 11.0f);
  CHECK(near(AM::CLAMP, 1.1f) == 13.0f);
  CHECK(near(AM::CLAMP, -0.1f) == 10.0f);
  CHECK(near(AM::CLAMP, 7.0f) == 13.0f);
  CHECK(near(AM::MIRROR, 1.1f) == 13.0f); // texel 4 mirrors to 3
  CHECK(near(AM::MIRROR, 1.3f) == 12.0f); // texel 5 mirrors to 2
  CHECK(near(AM::MIRROR, -0.1f) == 10.0f); // texel -1 mirrors to 0
  CHECK(near(AM::MIRROR, 2.1f) == 10.0f); // texel 8 = period 2*4 -> 0
  CHECK(near(AM::BORDER, 1.1f) == -1.0f); // border colour (red channel for float images)
  CHECK(near(AM::BORDER, -0.1f) == -1.0f);
  CHECK(near(AM::BORDER, 0.6f) == 12.0f);

  // Linear at u = 0 blends texel -1 and texel 0 half/half.
  CHECK(lin(AM::CLAMP, 0.0f) == Approx(10.0f));
  CHECK(lin(AM::WRAP, 0.0f) == Approx(11.5f));
  CHECK(lin(AM::MIRROR, 0.0f) == Approx(10.0f));
  CHECK(lin(AM::BORDER, 0.0f) == Approx(0.5f * (10.0f - 1.0f)));
  CHECK(lin(AM::WRAP, 1.0f) == Approx(11.5f));

  // float4 border colour comes back whole.
  const Image2D<float4> img4 = makeTestImage(2, 2);
  const float4 bc = img4.sample(makeSampler(AM::BORDER, Sampler::Filter::NEAREST), float2(-0.5f, 0.5f));
  CHECK((bc.x == -1.0f && bc.y == -2.0f && bc.z == -3.0f && bc.w == -4.0f));

  // Degenerate inputs must not crash.
  const float nanv = std::nanf("");
  CHECK(std::isfinite(near(AM::WRAP, nanv)));
  CHECK(std::isfinite(lin(AM::MIRROR, 1e30f)));
  CHECK(std::isfinite(lin(AM::WRAP, -INFINITY)));
  CHECK(Image2D<float>().sample(Sampler(), float2(0.5f, 0.5f)) == 0.0f);
}

TEST_CASE("Image2D EXR round trip is exact", "[liteimage]")
{
  const Image2D<float4> img = makeTestImage(7, 5);
  TempFile              tmp("exr");
  REQUIRE(SaveImage(tmp.path.c_str(), img));
  Image2D<float4> back;
  REQUIRE(LoadImage(tmp.path.c_str(), back));
  REQUIRE(back.width() == 7);
  REQUIRE(back.height() == 5);
  for (uint32_t y = 0; y < 5; y++)
    for (uint32_t x = 0; x < 7; x++)
      for (int c = 0; c < 4; c++)
        CHECK(back.at(int(x), int(y))[c] == img.at(int(x), int(y))[c]);

  // Grayscale float image, including values outside [0,1] which a float format must keep.
  Image2D<float> gray(3, 2);
  for (int i = 0; i < 6; i++)
    gray.data()[i] = -2.5f + 1.75f * float(i);
  TempFile gtmp("exr");
  REQUIRE(SaveImage(gtmp.path.c_str(), gray));
  Image2D<float> gback;
  REQUIRE(LoadImage(gtmp.path.c_str(), gback));
  REQUIRE(gback.vector().size() == 6);
  for (int i = 0; i < 6; i++)
    CHECK(gback.data()[i] == gray.data()[i]);
}

TEST_CASE("Image2D PNG round trip within 8-bit precision", "[liteimage]")
{
  Image2D<float4> img = makeTestImage(6, 4);
  img.set(0, 0, float4(2.0f, -1.0f, 0.5f, 1.0f)); // out of range values are clamped
  TempFile tmp("png");
  REQUIRE(SaveImage(tmp.path.c_str(), img));
  Image2D<float4> back;
  REQUIRE(LoadImage(tmp.path.c_str(), back));
  REQUIRE(back.width() == 6);
  REQUIRE(back.height() == 4);
  for (uint32_t y = 0; y < 4; y++)
    for (uint32_t x = 0; x < 6; x++)
      for (int c = 0; c < 4; c++)
      {
        const float expected = std::min(std::max(img.at(int(x), int(y))[c], 0.0f), 1.0f);
        CHECK(std::abs(back.at(int(x), int(y))[c] - expected) <= 1.0f / 255.0f);
      }
  CHECK(back.at(0, 0).x == 1.0f);
  CHECK(back.at(0, 0).y == 0.0f);

  // Packed RGBA8 round trip is exact, and loads back as floats value/255 (no gamma).
  Image2D<uint32_t> rgba(3, 3);
  for (int i = 0; i < 9; i++)
    rgba.data()[i] = uint32_t(i * 20) | (uint32_t(255 - i) << 8) | (uint32_t(i * 7) << 16) | (uint32_t(100 + i) << 24);
  TempFile rtmp("png");
  REQUIRE(SaveImage(rtmp.path.c_str(), rgba));
  Image2D<uint32_t> rback;
  REQUIRE(LoadImage(rtmp.path.c_str(), rback));
  REQUIRE(rback.vector().size() == 9);
  for (int i = 0; i < 9; i++)
    CHECK(rback.data()[i] == rgba.data()[i]);
  Image2D<float4> asFloat;
  REQUIRE(LoadImage(rtmp.path.c_str(), asFloat));
  CHECK(asFloat.at(1, 0).x == Approx(20.0f / 255.0f));
  CHECK(asFloat.at(1, 0).w == Approx(101.0f / 255.0f));

  // Grayscale PNG.
  Image2D<float> gray(2, 1);
  gray.data()[0] = 0.2f;
  gray.data()[1] = 0.9f;
  TempFile gtmp("png");
  REQUIRE(SaveImage(gtmp.path.c_str(), gray));
  Image2D<float> gback;
  REQUIRE(LoadImage(gtmp.path.c_str(), gback));
  CHECK(std::abs(gback.data()[0] - 0.2f) <= 1.0f / 255.0f);
  CHECK(std::abs(gback.data()[1] - 0.9f) <= 1.0f / 255.0f);
  // A grayscale file loads into an RGBA image as gray RGB with alpha 1.
  Image2D<float4> grayAsRGBA;
  REQUIRE(LoadImage(gtmp.path.c_str(), grayAsRGBA));
  CHECK(grayAsRGBA.at(1, 0).y == gback.data()[1]);
  CHECK(grayAsRGBA.at(1, 0).w == 1.0f);
}

TEST_CASE("Image2D formats without alpha", "[liteimage]")
{
  const Image2D<float4> img = makeTestImage(4, 3);
  for (const char* ext : {"hdr", "pfm", "ppm", "jpg"})
  {
    INFO("format " << ext);
    TempFile tmp(ext);
    REQUIRE(SaveImage(tmp.path.c_str(), img));
    Image2D<float4> back;
    REQUIRE(LoadImage(tmp.path.c_str(), back));
    CHECK(back.width() == 4);
    CHECK(back.height() == 3);
    CHECK(back.at(2, 1).w == 1.0f); // alpha dropped on save, restored as 1 on load
  }
  // PFM stores 32-bit floats: exact RGB.
  TempFile tmp("pfm");
  REQUIRE(SaveImage(tmp.path.c_str(), img));
  Image2D<float4> back;
  REQUIRE(LoadImage(tmp.path.c_str(), back));
  CHECK(back.at(3, 2).x == img.at(3, 2).x);
  CHECK(back.at(3, 2).z == img.at(3, 2).z);
  CHECK(back.at(0, 0).y == img.at(0, 0).y); // row 0 stays the top row
  CHECK(back.at(0, 2).y == img.at(0, 2).y);
}

TEST_CASE("Image2D IO failures return false", "[liteimage]")
{
  Image2D<float4> img4;
  Image2D<float>  img1;
  Image2D<uint32_t> imgU;
  CHECK_FALSE(LoadImage("/nonexistent/dir/missing_image.png", img4));
  CHECK_FALSE(LoadImage("/nonexistent/dir/missing_image.exr", img1));
  CHECK_FALSE(LoadImage("/nonexistent/dir/missing_image.png", imgU));
  CHECK_FALSE(LoadImage(nullptr, img4));
  CHECK_FALSE(SaveImage("/nonexistent/dir/out.png", makeTestImage(2, 2)));
  CHECK_FALSE(SaveImage("/tmp/crossrt_unknown_format.notanimageformat", makeTestImage(2, 2)));
  CHECK_FALSE(SaveImage("/tmp/crossrt_empty.png", Image2D<float4>()));

  // A file with garbage content.
  TempFile tmp("png");
  {
    std::FILE* f = std::fopen(tmp.path.c_str(), "wb");
    REQUIRE(f != nullptr);
    std::fputs("this is not a png", f);
    std::fclose(f);
  }
  CHECK_FALSE(LoadImage(tmp.path.c_str(), img4));
}

TEST_CASE("SaveBMP writes packed RGBA8 pixels as a BMP that reads back", "[liteimage]")
{
  const std::vector<unsigned int> pixels = {0x000000FFu, 0x0000FF00u, 0x00FF0000u, 0xFF102030u, 0x00FFFFFFu, 0x00000000u};
  TempFile tmp("bmp");
  REQUIRE(SaveBMP(tmp.path.c_str(), pixels.data(), 3, 2));
  Image2D<uint32_t> back;
  REQUIRE(LoadImage(tmp.path.c_str(), back));
  REQUIRE(back.width() == 3);
  REQUIRE(back.height() == 2);
  for (size_t i = 0; i < pixels.size(); i++)  // alpha is dropped: reads back as 255
    CHECK(back.data()[i] == ((pixels[i] & 0x00FFFFFFu) | 0xFF000000u));
  CHECK_FALSE(SaveBMP("/nonexistent/dir/out.bmp", pixels.data(), 3, 2));
  CHECK_FALSE(SaveBMP(tmp.path.c_str(), nullptr, 3, 2));
  CHECK_FALSE(SaveBMP(tmp.path.c_str(), pixels.data(), 0, 2));
}

TEST_CASE("Combined image samplers read every texel type as Vulkan does", "[liteimage]")
{
  Sampler nearest = makeSampler(Sampler::AddressMode::CLAMP, Sampler::Filter::NEAREST);
  // RGBA8 unorm, R in the lowest byte.
  const std::vector<uint32_t> rgba = {0x80FF4000u, 0x00000000u};
  auto bytes = MakeCombinedTexture2D(std::make_shared<Image2D<uint32_t>>(2, 1, rgba.data()), nearest);
  const float4 t0 = bytes->sample(float2(0.25f, 0.5f));
  CHECK(t0.x == 0.0f);
  CHECK(t0.y == 64.0f / 255.0f);
  CHECK(t0.z == 1.0f);
  CHECK(t0.w == 128.0f / 255.0f);
  CHECK(bytes->width() == 2);
  CHECK(bytes->bpp() == 4);
  CHECK(bytes->format() == 37u);  // VK_FORMAT_R8G8B8A8_UNORM
  // float as (v, 0, 0, 1); BORDER gives the border colour whatever the texels are.
  const std::vector<float> gray = {0.5f, 2.0f};
  auto floats = MakeCombinedTexture2D(std::make_shared<Image2D<float>>(2, 1, gray.data()), makeSampler(Sampler::AddressMode::BORDER, Sampler::Filter::NEAREST));
  const float4 f1 = floats->sample(float2(0.75f, 0.5f)), outside = floats->sample(float2(1.5f, 0.5f));
  CHECK((f1.x == 2.0f && f1.y == 0.0f && f1.z == 0.0f && f1.w == 1.0f));
  CHECK((outside.x == -1.0f && outside.y == -2.0f && outside.z == -3.0f && outside.w == -4.0f));
  // float4 images sample bit for bit as Image2D<float4> does, and the image is shared, not copied.
  auto image = std::make_shared<Image2D<float4>>(makeTestImage(5, 3));
  const Sampler linear = makeSampler(Sampler::AddressMode::MIRROR, Sampler::Filter::LINEAR);
  auto shared = MakeCombinedTexture2D(image, linear);
  image->set(1, 1, float4(9.0f));
  for (float u = -1.3f; u < 2.0f; u += 0.173f)
  {
    const float4 a = shared->sample(float2(u, 0.61f - u)), b = image->sample(linear, float2(u, 0.61f - u));
    REQUIRE((a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w));
  }
  // The textures a GPU gets sample as the combined samplers do.
  const std::vector<std::shared_ptr<ICombinedImageSampler>> list = {bytes, floats, shared, nullptr};
  const std::vector<Texture2D<float4>> textures = TexturesOf(list);
  REQUIRE(textures.size() == 4);
  CHECK(textures[3].width() == 0);
  for (size_t i = 0; i < 3; i++)
    for (float u = -0.7f; u < 1.8f; u += 0.117f)
    {
      const float4 a = list[i]->sample(float2(u, 1.0f - u)), b = textures[i].sample(float2(u, 1.0f - u));
      REQUIRE((a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w));
    }
  // A combined sampler of the user's own has no texels that stand for its sample().
  struct Procedural : ICombinedImageSampler
  {
    float4       sample(float2 uv) const override { return float4(uv.x, uv.y, 0.0f, 1.0f); }
    unsigned int width() const override { return 1; }
    unsigned int height() const override { return 1; }
    unsigned int depth() const override { return 1; }
    unsigned int bpp() const override { return 16; }
    unsigned int format() const override { return 109; }
    Sampler      sampler() const override { return Sampler(); }
    const void*  data() const override { return nullptr; }
  } procedural;
  CHECK_THROWS_AS(TextureOf(&procedural), std::invalid_argument);
}

TEST_CASE("LoadBMP reads what SaveBMP wrote, sRGB images sample linearized through combined samplers", "[liteimage]")
{
  const std::vector<unsigned int> pixels = {0x00336699u, 0x00FFFFFFu};
  TempFile tmp("bmp");
  REQUIRE(SaveBMP(tmp.path.c_str(), pixels.data(), 2, 1));
  int w = -1, h = -1;
  const std::vector<unsigned int> back = LoadBMP(tmp.path.c_str(), &w, &h);
  REQUIRE((w == 2 && h == 1 && back.size() == 2));
  CHECK(back[0] == 0xFF336699u);
  CHECK(LoadBMP("/nonexistent/dir/in.bmp", &w, &h).empty());
  CHECK((w == 0 && h == 0));

  auto image = std::make_shared<Image2D<uint32_t>>(2, 1, pixels.data());
  image->setSRGB(true);
  auto combined = MakeCombinedTexture2D(image, makeSampler(Sampler::AddressMode::CLAMP, Sampler::Filter::NEAREST));
  CHECK(combined->format() == 43u);  // VK_FORMAT_R8G8B8A8_SRGB
  const float4 c = combined->sample(float2(0.25f, 0.5f));
  CHECK(c.x == Approx(std::pow((153.0f / 255.0f + 0.055f) / 1.055f, 2.4f)));  // 0x99, red
  CHECK(c.z == Approx(std::pow((51.0f / 255.0f + 0.055f) / 1.055f, 2.4f)));   // 0x33, blue
  CHECK(c.w == 0.0f);                                                          // alpha stays linear
  const float4 white = combined->sample(float2(0.75f, 0.5f));
  CHECK(white.x == 1.0f);
}

TEST_CASE("Image2D MIRROR_ONCE mirrors once around 0, then clamps (Vulkan's mirror clamp to edge)", "[liteimage]")
{
  const std::vector<float> row = {1.0f, 2.0f, 3.0f, 4.0f};
  Image2D<float> img(4, 1, row.data());
  Sampler s = makeSampler(Sampler::AddressMode::MIRROR_ONCE, Sampler::Filter::NEAREST);
  auto at = [&](int texel) { return img.sample(s, float2((float(texel) + 0.5f) / 4.0f, 0.5f)); };
  CHECK(at(0) == 1.0f);
  CHECK(at(3) == 4.0f);
  CHECK(at(-1) == 1.0f);  // mirrored
  CHECK(at(-4) == 4.0f);
  CHECK(at(-9) == 4.0f);  // then clamped
  CHECK(at(6) == 4.0f);   // past the far edge: clamped
}
