#include "CombinedSamplers.h"

using LiteImage::Image2D;
using LiteImage::MakeCombinedTexture2D;
using LiteImage::Sampler;
using namespace LiteMath;

// Coordinates a little outside [0, 1], so that every address mode matters.
static inline float2 get_uv(const int x, const int y, const int width, const int height)
{
  return float2((float(x) + 0.5f) / float(width), (float(y) + 0.5f) / float(height)) * 1.6f - float2(0.3f, 0.3f);
}

static Sampler MakeSampler(Sampler::Filter a_filter, Sampler::AddressMode a_mode)
{
  Sampler sampler;
  sampler.filter   = a_filter;
  sampler.addressU = a_mode;
  sampler.addressV = a_mode;
  sampler.borderColor = float4(0.0f, 0.0f, 0.0f, 1.0f);
  return sampler;
}

template <typename T>
static std::shared_ptr<Image2D<T>> MakeImage(unsigned a_width, unsigned a_height, T (*a_texel)(unsigned))
{
  std::vector<T> texels(a_width * a_height);
  for (unsigned i = 0; i < texels.size(); ++i)
    texels[i] = a_texel(i);
  return std::make_shared<Image2D<T>>(a_width, a_height, texels.data());
}

static uint32_t Bytes(unsigned i) { return (i * 2654435761u) ^ 0x5A3C96E1u; }
static float    Gray(unsigned i) { return float((i * 37u) % 17u) / 8.0f - 0.5f; }
static float4   Color(unsigned i) { return float4(float(i % 5u) / 4.0f, float(i % 3u) / 2.0f, float(i % 7u) / 6.0f, 1.0f); }

CombinedSamplers::CombinedSamplers()
{
  m_logoImage    = MakeImage<uint32_t>(5, 3, Bytes);
  m_pLogo        = MakeCombinedTexture2D(m_logoImage, MakeSampler(Sampler::Filter::LINEAR, Sampler::AddressMode::MIRROR));
  m_pMaskStorage = MakeCombinedTexture2D(MakeImage<float>(4, 4, Gray), MakeSampler(Sampler::Filter::NEAREST, Sampler::AddressMode::BORDER));
  m_pMask        = m_pMaskStorage.get();

  m_textures.push_back(MakeCombinedTexture2D(MakeImage<uint32_t>(3, 3, Bytes), MakeSampler(Sampler::Filter::NEAREST, Sampler::AddressMode::CLAMP)));
  m_textures.push_back(MakeCombinedTexture2D(MakeImage<float4>(7, 5, Color), MakeSampler(Sampler::Filter::LINEAR, Sampler::AddressMode::WRAP)));
  m_textures.push_back(MakeCombinedTexture2D(MakeImage<float>(6, 2, Gray), MakeSampler(Sampler::Filter::LINEAR, Sampler::AddressMode::CLAMP)));
  m_textures.push_back(MakeCombinedTexture2D(MakeImage<uint32_t>(2, 2, Bytes), MakeSampler(Sampler::Filter::NEAREST, Sampler::AddressMode::WRAP)));
  for (size_t i = 0; i < m_textures.size(); ++i)
    m_views.push_back(m_textures[(i + 2) % m_textures.size()].get());
}

void CombinedSamplers::Run(const int a_width, const int a_height, float4* a_out)
{
  kernel2D_Run(a_width, a_height, a_out);
}

void CombinedSamplers::kernel2D_Run(const int a_width, const int a_height, float4* a_out)
{
  for (int y = 0; y < a_height; ++y)
  {
    for (int x = 0; x < a_width; ++x)
    {
      const float2 uv = get_uv(x, y, a_width, a_height);
      const int    id = (x * 7 + y * 3) % int(m_textures.size());
      float4 color    = m_pLogo->sample(uv) + Tinted(uv, id);
      color += m_views[(id + 1) % int(m_views.size())]->sample(uv * 0.5f);
      color += m_pMask->sample(uv) * float(m_pMask->width() + m_textures[id]->height());
      a_out[y * a_width + x] = color;
    }
  }
}
