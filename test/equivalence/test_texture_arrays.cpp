// Arrays of textures: the original TexturedMaterials, TexturedMaterials_CPU and
// TexturedMaterials_Vulkan give the same samples. Each texture has its own size, address modes
// and filter; threads pick textures by index. Where the device has no descriptor indexing (lavapipe)
// the kernels sample from buffers exactly as LiteImage does, so the results are bit for bit the
// CPU's; with the GPU's samplers bilinear weights have its sub-texel precision.
#include "TexturedMaterials.h"
#include "TexturedMaterials_CPU.h"
#include "TexturedMaterials_Vulkan.h"
#include "TexturedHits.h"
#include "TexturedHits_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "TexturedHits_ISPC.h"
#include "TexturedMaterials_ISPC.h"
#endif
#include "TexturedHits_Vulkan.h"
#include "CombinedSamplers.h"
#include "CombinedSamplers_CPU.h"
#include "CombinedSamplers_Vulkan.h"
#ifdef CROSSRT_HAS_ISPC
#include "CombinedSamplers_ISPC.h"
#endif
#include "ImageSupport.h"
#include "TestSupport.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

using LiteImage::Image2D;
using LiteImage::Sampler;
using LiteImage::Texture2D;
using LiteMath::float2;
using LiteMath::float4;

namespace
{
using Mode = Sampler::AddressMode;

Sampler MakeSampler(Mode u, Mode v, bool linear, float4 border = float4(0.0f))
{
  Sampler s;
  s.addressU = u;
  s.addressV = v;
  s.filter = linear ? Sampler::Filter::LINEAR : Sampler::Filter::NEAREST;
  s.borderColor = border;
  return s;
}

// Five albedo textures: sizes that are not powers of two, one empty, every address mode, both filters.
void Fill(TexturedMaterials& m)
{
  m.m_albedo.clear();
  m.m_albedo.emplace_back(RandomImage(7, 5, 1), MakeSampler(Mode::WRAP, Mode::WRAP, false));
  m.m_albedo.emplace_back(RandomImage(16, 9, 2), MakeSampler(Mode::MIRROR, Mode::MIRROR, true));
  m.m_albedo.emplace_back(RandomImage(3, 1, 3), MakeSampler(Mode::BORDER, Mode::BORDER, true, float4(0.0f, 0.0f, 0.0f, 1.0f)));
  m.m_albedo.emplace_back(Image2D<float4>(), MakeSampler(Mode::WRAP, Mode::WRAP, true));
  m.m_albedo.emplace_back(RandomImage(5, 4, 4), MakeSampler(Mode::MIRROR_ONCE, Mode::WRAP, true));
  const auto a = RandomFloats(11 * 3, 5, -2.0f, 2.0f), b = RandomFloats(4 * 4, 6, -2.0f, 2.0f);
  m.m_bumps.clear();
  m.m_bumps.emplace_back(Image2D<float>(11, 3, a.data()), MakeSampler(Mode::CLAMP, Mode::CLAMP, true));
  m.m_bumps.emplace_back(Image2D<float>(4, 4, b.data()), MakeSampler(Mode::MIRROR, Mode::BORDER, false, float4(1.0f)));
}

struct Hits
{
  std::vector<uint32_t> ids;
  std::vector<float2> uvs;
};

// Random texture ids and coordinates in and around [0, 1], and a few extremes: huge, infinite and NaN.
Hits RandomHits(int n)
{
  Hits h;
  const auto c = RandomFloats(3 * n, 11, -1.5f, 2.5f);
  for (int i = 0; i < n; ++i)
  {
    h.ids.push_back(uint32_t(c[3 * i] * 1000.0f + 2000.0f));
    h.uvs.push_back(float2(c[3 * i + 1], c[3 * i + 2]));
  }
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const float2 extremes[] = {float2(1.0e9f, -1.0e9f), float2(inf, 0.5f), float2(0.5f, -inf), float2(nan, 0.25f), float2(0.0f, 1.0f)};
  for (int i = 0; i < n && i < 5 * 5; ++i) h.uvs[i] = extremes[i % 5];  // ids i % 5 cover every texture with each
  for (int i = 0; i < n && i < 5 * 5; ++i) h.ids[i] = uint32_t(i / 5);
  return h;
}

struct Shaded
{
  std::vector<float4> colors, texels;
  std::vector<float> heights;
};

Shaded Shade(TexturedMaterials& m, const Hits& h)
{
  const int n = int(h.ids.size());
  Shaded s{std::vector<float4>(n, float4(-7.0f)), std::vector<float4>(n, float4(-7.0f)), std::vector<float>(n, -7.0f)};
  m.Shade(n, h.ids.data(), h.uvs.data(), s.colors.data(), s.heights.data(), s.texels.data());
  return s;
}

bool Same(const float4& a, const float4& b) { return a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w; }

// Hit i shaded alike but for the GPU's sampler: 8 bits of sub-texel precision (the height map's
// slopes amplify them), and nearest may pick the other texel at an edge.
bool SamplerClose(const Shaded& a, const Shaded& b, size_t i)
{
  return MaxDifference(a.colors[i], b.colors[i]) <= 4.0f / 512.0f && std::fabs(a.heights[i] - b.heights[i]) <= 16.0f / 512.0f;
}
}  // namespace

TEST_CASE("Arrays of textures: each its own size, address modes and filter, picked per thread", "[equivalence][textures][device-features]")
{
  auto ctx = ValidatedContext();
  const Hits hits = RandomHits(4001);
  TexturedMaterials reference;
  Fill(reference);
  const Shaded expected = Shade(reference, hits);

  // The original itself, against what the test computes: nearest WRAP texels of texture 0, the
  // empty texture's zeros, and every texture picked.
  std::vector<int> picked(5, 0);
  for (size_t i = 0; i < hits.ids.size(); ++i)
  {
    const uint32_t id = hits.ids[i] % 5;
    ++picked[id];
    if (id == 3) REQUIRE(Same(expected.colors[i], float4(0.0f)));
    if (id == 0 && i >= 25)
    {
      const auto& t = reference.m_albedo[0];
      const int x = int(std::floor(hits.uvs[i].x * 7.0f)), y = int(std::floor(hits.uvs[i].y * 5.0f));
      REQUIRE(Same(expected.colors[i], t.image().at(((x % 7) + 7) % 7, ((y % 5) + 5) % 5)));
    }
  }
  for (int count : picked) REQUIRE(count > 400);

  std::vector<std::pair<const char*, std::shared_ptr<TexturedMaterials>>> impls = {{"CPU", CreateTexturedMaterials_CPU()}};
#ifdef CROSSRT_HAS_ISPC
  impls.push_back({"ISPC", CreateTexturedMaterials_ISPC()});  // LiteImage's sampling, per lane: exact
#endif
  if (ctx) impls.push_back({"Vulkan", CreateTexturedMaterials_Vulkan(ctx)});
  for (auto& [name, impl] : impls)
  {
    INFO(name);
    Fill(*impl);
    const Shaded got = Shade(*impl, hits);
    auto* vulkan = dynamic_cast<TexturedMaterials_Vulkan*>(impl.get());
    const bool exact = !vulkan || !vulkan->UsesTextureHardware();
    size_t near = 0;
    for (size_t i = 0; i < hits.ids.size(); ++i)
    {
      INFO("hit " << i << ": texture " << hits.ids[i] % 5 << " at uv " << hits.uvs[i].x << ", " << hits.uvs[i].y);
      REQUIRE(Same(got.texels[i], expected.texels[i]));
      if (exact)
      {
        REQUIRE(Same(got.colors[i], expected.colors[i]));
        REQUIRE(got.heights[i] == expected.heights[i]);
      }
      else
        near += SamplerClose(got, expected, i);
    }
    if (!exact) CHECK(near >= hits.ids.size() * 98 / 100);
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Arrays of textures: changed, added and emptied textures reach the GPU", "[equivalence][textures][device-features]")
{
  auto ctx = ValidatedContext();
  if (!ctx) return;
  auto gpu = CreateTexturedMaterials_Vulkan(ctx);
  TexturedMaterials cpu;
  Fill(*gpu);
  Fill(cpu);
  const Hits hits = RandomHits(501);
  auto agree = [&] {
    const Shaded a = Shade(cpu, hits), b = Shade(*gpu, hits);
    size_t same = 0;
    std::ostringstream differing;
    for (size_t i = 0; i < hits.ids.size(); ++i)
    {
      const bool close = SamplerClose(a, b, i);
      same += close;
      if (!close && differing.tellp() < 600)
        differing << " hit " << i << " (texture " << hits.ids[i] % 5 << ", uv " << hits.uvs[i].x << ", " << hits.uvs[i].y << "): colour "
                  << a.colors[i].x << " vs " << b.colors[i].x << ", height " << a.heights[i] << " vs " << b.heights[i] << ";";
    }
    UNSCOPED_INFO(same << " of " << hits.ids.size() << " close;" << differing.str());
    return same >= hits.ids.size() * 98 / 100;
  };
  REQUIRE(agree());
  // New texels and a new sampler, same sizes: CommitDeviceData() sends them.
  for (auto* m : {gpu.get(), &cpu})
  {
    m->m_albedo[1].image() = RandomImage(16, 9, 21);
    m->m_albedo[1].sampler() = MakeSampler(Mode::CLAMP, Mode::WRAP, false);
    m->CommitDeviceData();
  }
  REQUIRE(agree());
  // One more texture: the next call commits by itself.
  for (auto* m : {gpu.get(), &cpu})
    m->m_albedo.emplace_back(RandomImage(2, 3, 22), MakeSampler(Mode::MIRROR, Mode::CLAMP, true));
  REQUIRE(agree());
  // One texture only, and an empty bump map.
  for (auto* m : {gpu.get(), &cpu})
  {
    m->m_albedo.resize(1);
    m->m_bumps[0] = Texture2D<float>();
  }
  REQUIRE(agree());
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Arrays of textures: the GPU's samplers only where the device has descriptor indexing", "[equivalence][textures][device-features]")
{
  auto ctx = ValidatedContext();
  if (!ctx) return;
  auto gpu = std::dynamic_pointer_cast<TexturedMaterials_Vulkan>(CreateTexturedMaterials_Vulkan(ctx));
  REQUIRE(gpu);
  CHECK(gpu->UsesTextureHardware() == ctx->hasTextureArrays);
  if (ctx->hasTextureArrays)
  {
    CHECK(ctx->maxTextureArraySize > 0);
    gpu->UseTextureHardware(false);  // and back: both ways work
    CHECK_FALSE(gpu->UsesTextureHardware());
    gpu->UseTextureHardware(true);
    CHECK(gpu->UsesTextureHardware());
  }
  else
  {
    REQUIRE_THROWS_WITH(gpu->UseTextureHardware(true), Catch::Contains("no arrays of textures (descriptor indexing)"));
    CHECK_FALSE(gpu->UsesTextureHardware());
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("Arrays of textures with ray queries in one kernel: the texture of the mesh each ray hits", "[equivalence][textures][composition][device-features]")
{
  auto ctx = ValidatedContext();
  // Two meshes: a unit quad at z = 0 and a triangle in front of part of it at z = 0.5.
  const float quad[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const uint32_t quadIndices[] = {0, 1, 2, 0, 2, 3};
  const float triangle[] = {-0.5f, -0.5f, 0.5f, 0.6f, -0.4f, 0.5f, 0.0f, 0.7f, 0.5f};
  const uint32_t triangleIndices[] = {0, 1, 2};
  auto configure = [&](TexturedHits& t) {
    auto scene = MakeSceneRT("lbvh");
    scene->AddInstance(scene->AddGeom_Triangles3f(quad, 4, quadIndices, 6), LiteMath::float4x4());
    scene->AddInstance(scene->AddGeom_Triangles3f(triangle, 3, triangleIndices, 3), LiteMath::float4x4());
    scene->CommitScene();
    t.SetScene(scene);
    t.m_meshTextures.clear();
    t.m_meshTextures.emplace_back(RandomImage(9, 6, 31), MakeSampler(Mode::WRAP, Mode::CLAMP, true));
    t.m_meshTextures.emplace_back(RandomImage(4, 5, 32), MakeSampler(Mode::MIRROR, Mode::WRAP, false));
  };
  // An orthographic grid of rays down -z over [-1.3, 1.3]^2: some miss, some hit each mesh.
  const int side = 61, n = side * side;
  std::vector<float4> org(n), dir(n, float4(0.0f, 0.0f, -1.0f, 1e30f));
  for (int i = 0; i < n; ++i) org[i] = float4(-1.3f + 2.6f * float(i % side) / float(side - 1), -1.3f + 2.6f * float(i / side) / float(side - 1), 2.0f, 0.0f);

  TexturedHits reference;
  configure(reference);
  std::vector<float4> expected(n);
  reference.Shade(n, org.data(), dir.data(), expected.data());
  int black = 0;
  for (auto& c : expected) black += Same(c, float4(0.0f));
  REQUIRE(black > n / 10);  // the misses
  REQUIRE(black < n / 2);

  std::vector<std::pair<const char*, std::shared_ptr<TexturedHits>>> impls = {{"CPU", CreateTexturedHits_CPU()}};
#ifdef CROSSRT_HAS_ISPC
  impls.push_back({"ISPC", CreateTexturedHits_ISPC()});
#endif
  if (ctx) impls.push_back({"Vulkan", CreateTexturedHits_Vulkan(ctx)});
  for (auto& [name, impl] : impls)
  {
    INFO(name);
    configure(*impl);
    std::vector<float4> colors(n, float4(-7.0f));
    impl->Shade(n, org.data(), dir.data(), colors.data());
    // Barycentrics from another traversal differ in the last bits: nearest samples may pick the
    // neighbouring texel right at an edge. The GPU's samplers weigh texels with a few bits of
    // sub-texel precision (8 on NVIDIA): their bilinear results are as close as SamplerClose's.
    auto* vulkan = dynamic_cast<TexturedHits_Vulkan*>(impl.get());
    const float tolerance = vulkan && vulkan->UsesTextureHardware() ? 4.0f / 512.0f : 1e-3f;
    size_t close = 0;
    for (int i = 0; i < n; ++i) close += MaxDifference(colors[i], expected[i]) <= tolerance;
    CHECK(close >= size_t(n) * 99 / 100);
  }
  RequireNoValidationMessages(ctx);
}

namespace
{
std::vector<float4> RunCombined(CombinedSamplers& c, int w, int h)
{
  std::vector<float4> out(size_t(w) * h, float4(-7.0f));
  c.Run(w, h, out.data());
  return out;
}
}  // namespace

// kernel_slicer's form of combined image samplers: ICombinedImageSampler pointers, one and vectors
// of them, over RGBA8, float and float4 images; sampled from buffers (lavapipe) bit for bit as
// their sample() does.
TEST_CASE("ICombinedImageSampler members (kernel_slicer's form) sample as on the CPU", "[equivalence][textures][device-features]")
{
  auto ctx = ValidatedContext();
  const int w = 37, h = 23;
  CombinedSamplers reference;
  const std::vector<float4> expected = RunCombined(reference, w, h);
  // The original against what the test computes: pixel (0, 0) from each sampler's own sample().
  {
    const float2 uv = float2(0.5f / w, 0.5f / h) * 1.6f - float2(0.3f, 0.3f);
    const float4 want = reference.m_pLogo->sample(uv) + clamp(reference.m_textures[0]->sample(uv), 0.0f, 1.0f) * 2.0f +
                        reference.m_views[1]->sample(uv * 0.5f) + reference.m_pMask->sample(uv) * float(4 + 3);
    REQUIRE(Same(expected[0], want));
  }
  std::vector<std::pair<const char*, std::shared_ptr<CombinedSamplers>>> impls = {{"CPU", CreateCombinedSamplers_CPU()}};
#ifdef CROSSRT_HAS_ISPC
  impls.push_back({"ISPC", CreateCombinedSamplers_ISPC()});
#endif
  if (ctx) impls.push_back({"Vulkan", CreateCombinedSamplers_Vulkan(ctx)});
  for (auto& [name, impl] : impls)
  {
    INFO(name);
    auto* vulkan = dynamic_cast<CombinedSamplers_Vulkan*>(impl.get());
    const bool exact = !vulkan || !vulkan->UsesTextureHardware();
    auto agree = [&](const std::vector<float4>& want) {
      const std::vector<float4> got = RunCombined(*impl, w, h);
      size_t same = 0;
      for (size_t i = 0; i < want.size(); ++i)
        same += exact ? Same(got[i], want[i]) : MaxDifference(got[i], want[i]) <= 16.0f / 512.0f;
      UNSCOPED_INFO(same << " of " << want.size() << " pixels agree; pixel 1: " << got[1].x << " vs " << want[1].x);
      return exact ? same == want.size() : same >= want.size() * 98 / 100;
    };
    REQUIRE(agree(expected));
    CombinedSamplers original;  // changed as the translated class is
    // New texels in a shared image: CommitDeviceData() sends them.
    for (auto* c : {impl.get(), &original})
    {
      c->m_logoImage->set(2, 1, 0xFFFFFFFFu);
      c->m_logoImage->set(0, 0, 0x00000000u);
      c->CommitDeviceData();
    }
    const std::vector<float4> changed = RunCombined(original, w, h);
    REQUIRE_FALSE(std::equal(changed.begin(), changed.end(), expected.begin(), Same));
    REQUIRE(agree(changed));
    // One texture fewer: the next call sees it by itself.
    for (auto* c : {impl.get(), &original})
    {
      c->m_views.erase(std::find(c->m_views.begin(), c->m_views.end(), c->m_textures.back().get()));  // it points into m_textures
      c->m_textures.pop_back();
    }
    REQUIRE(agree(RunCombined(original, w, h)));
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("An ICombinedImageSampler of the user's own is an error on the GPU, not a wrong sample", "[equivalence][textures]")
{
  auto ctx = ValidatedContext();
  if (!ctx) return;
  struct Procedural : ICombinedImageSampler
  {
    float4 sample(float2 uv) const override { return float4(uv.x, uv.y, 0.0f, 1.0f); }
    unsigned int width() const override { return 1; }
    unsigned int height() const override { return 1; }
    unsigned int depth() const override { return 1; }
    unsigned int bpp() const override { return 16; }
    unsigned int format() const override { return 109; }
    Sampler sampler() const override { return Sampler(); }
    const void* data() const override { return &texel; }
    float4 texel = float4(1.0f);
  };
  auto gpu = CreateCombinedSamplers_Vulkan(ctx);
  gpu->m_pLogo = std::make_shared<Procedural>();
  std::vector<float4> out(4);
  try
  {
    gpu->Run(2, 2, out.data());
    FAIL("a procedural ICombinedImageSampler was sampled on the GPU");
  }
  catch (const std::invalid_argument& e)
  {
    CHECK(std::string(e.what()).find("MakeCombinedTexture2D") != std::string::npos);
  }
}
