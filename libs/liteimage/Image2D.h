// LiteImage: a minimal 2D image container with a Vulkan-like sampler and image file IO.
#pragma once

#include "LiteMath.h"

#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

namespace LiteImage
{
using LiteMath::float2;
using LiteMath::float4;
using LiteMath::int2;

// Mirrors the relevant part of VkSamplerCreateInfo. Defaults: WRAP (repeat) + NEAREST.
// MIRROR_ONCE is Vulkan's mirror-clamp-to-edge: mirrored once around 0, then clamped.
struct Sampler
{
  enum class AddressMode { WRAP = 0, MIRROR = 1, CLAMP = 2, BORDER = 3, MIRROR_ONCE = 4 };
  enum class Filter { NEAREST = 0, LINEAR = 1 };

  AddressMode addressU    = AddressMode::WRAP;
  AddressMode addressV    = AddressMode::WRAP;
  Filter      filter      = Filter::NEAREST;
  float4      borderColor = float4(0.0f); // returned for texels outside the image in BORDER mode
  // The rest of kernel_slicer's LiteImage::Sampler, for code that sets or compares them. Images
  // here are 2D with one mip level: the third axis, anisotropy and the level of detail do not apply.
  AddressMode addressW      = AddressMode::WRAP;
  uint32_t    maxAnisotropy = 1;
  uint32_t    maxLOD        = 32;
  uint32_t    minLOD        = 0;
  uint32_t    mipLODBias    = 0;
};

namespace detail
{
// Maps a (possibly out of range) texel index into [0, size) or returns -1 for BORDER.
inline int addressTexel(int i, int size, Sampler::AddressMode mode)
{
  switch (mode)
  {
  case Sampler::AddressMode::WRAP:
    return ((i % size) + size) % size;
  case Sampler::AddressMode::MIRROR:
  {
    // Mirrored repeat has period 2*size: 0..size-1 forward, then size-1..0 backward.
    const int period = 2 * size;
    const int m      = ((i % period) + period) % period;
    return m < size ? m : period - 1 - m;
  }
  case Sampler::AddressMode::CLAMP:
    return i < 0 ? 0 : (i >= size ? size - 1 : i);
  case Sampler::AddressMode::MIRROR_ONCE:
  {
    const int m = i < 0 ? -1 - i : i;
    return m >= size ? size - 1 : m;
  }
  case Sampler::AddressMode::BORDER:
  default:
    return (i < 0 || i >= size) ? -1 : i;
  }
}

// Border colour converted to the texel type (float images use the red channel).
inline void borderValue(const float4& c, float& out) { out = c.x; }
inline void borderValue(const float4& c, float4& out) { out = c; }

// Texel-space coordinate made safe for float->int conversion (NaN -> 0, huge values bounded).
inline float sanitizeCoord(float x)
{
  if (!(x == x))
    return 0.0f;
  return x < -1.0e8f ? -1.0e8f : (x > 1.0e8f ? 1.0e8f : x);
}
} // namespace detail

template <typename T>
class Image2D
{
public:
  Image2D() = default;
  Image2D(uint32_t a_width, uint32_t a_height, const T* a_data = nullptr) { resize(a_width, a_height, a_data); }
  Image2D(uint32_t a_width, uint32_t a_height, T a_fill)
      : m_width(a_width), m_height(a_height), m_data(size_t(a_width) * a_height, a_fill)
  {
  }

  uint32_t width() const { return m_width; }
  uint32_t height() const { return m_height; }

  // Pixels are contiguous, row-major, row 0 is the top row of the image file.
  T*                    data() { return m_data.data(); }
  const T*              data() const { return m_data.data(); }
  std::vector<T>&       vector() { return m_data; }
  const std::vector<T>& vector() const { return m_data; }

  T&       operator[](const int2& p) { return m_data[index(p.x, p.y)]; }
  const T& operator[](const int2& p) const { return m_data[index(p.x, p.y)]; }
  T&       at(int x, int y) { return m_data[index(x, y)]; }
  const T& at(int x, int y) const { return m_data[index(x, y)]; }
  void     set(int x, int y, const T& v) { m_data[index(x, y)] = v; }

  // Resizes to w x h; copies w*h texels from a_data when given, otherwise value-initializes.
  void resize(uint32_t a_width, uint32_t a_height, const T* a_data = nullptr)
  {
    m_width  = a_width;
    m_height = a_height;
    if (a_data != nullptr)
      m_data.assign(a_data, a_data + size_t(a_width) * a_height);
    else
      m_data.assign(size_t(a_width) * a_height, T());
  }
  void clear()
  {
    m_width = m_height = 0;
    m_data.clear();
    m_data.shrink_to_fit();
  }

  // Whether 8-bit texels hold sRGB-encoded colour (as LiteImage's setSRGB): combined image samplers
  // read them linearized, as a GPU reads VK_FORMAT_R8G8B8A8_SRGB. sample() and the IO ignore it.
  void setSRGB(bool a_srgb) { m_srgb = a_srgb; }
  bool srgb() const { return m_srgb; }

  // Samples with normalized coordinates; texel centers are at ((i + 0.5) / w, (j + 0.5) / h)
  // as in Vulkan. Implemented for T = float and T = float4. An empty image returns T().
  T sample(const Sampler& a_sampler, float2 a_uv) const;

private:
  size_t index(int x, int y) const { return size_t(y) * m_width + size_t(x); }

  // Fetch one texel after address-mode remapping; BORDER outside the image yields the border colour.
  T fetch(const Sampler& s, int x, int y) const
  {
    const int xi = detail::addressTexel(x, int(m_width), s.addressU);
    const int yi = detail::addressTexel(y, int(m_height), s.addressV);
    if (xi < 0 || yi < 0)
    {
      T border{};
      detail::borderValue(s.borderColor, border);
      return border;
    }
    return m_data[index(xi, yi)];
  }

  uint32_t       m_width  = 0;
  uint32_t       m_height = 0;
  std::vector<T> m_data;
  bool           m_srgb = false;
};

namespace detail
{
// Nearest or bilinear filtering of a w x h grid of texels with normalized coordinates, texel
// centers at ((i + 0.5) / w, (j + 0.5) / h) as in Vulkan. fetch(x, y) gives the texel (of type R)
// at a possibly out-of-range index, after the sampler's address modes. Every sample() of LiteImage
// is this one sequence of float operations, which the GPU's buffer sampling repeats exactly.
template <typename R, typename Fetch>
R filterTexels(uint32_t a_width, uint32_t a_height, const Sampler& a_sampler, float2 a_uv, const Fetch& fetch)
{
  if (a_width == 0 || a_height == 0)
    return R();

  const float x = sanitizeCoord(a_uv.x * float(a_width));
  const float y = sanitizeCoord(a_uv.y * float(a_height));

  if (a_sampler.filter == Sampler::Filter::NEAREST)
    return fetch(int(std::floor(x)), int(std::floor(y)));

  // Bilinear: shift by half a texel so that integer positions are texel centers.
  const float fx = x - 0.5f, fy = y - 0.5f;
  const float x0 = std::floor(fx), y0 = std::floor(fy);
  const float tx = fx - x0, ty = fy - y0;
  const int   ix = int(x0), iy = int(y0);

  const R t00 = fetch(ix, iy);
  const R t10 = fetch(ix + 1, iy);
  const R t01 = fetch(ix, iy + 1);
  const R t11 = fetch(ix + 1, iy + 1);
  const R top    = t00 * (1.0f - tx) + t10 * tx;
  const R bottom = t01 * (1.0f - tx) + t11 * tx;
  return top * (1.0f - ty) + bottom * ty;
}
} // namespace detail

template <typename T>
T Image2D<T>::sample(const Sampler& a_sampler, float2 a_uv) const
{
  return detail::filterTexels<T>(m_width, m_height, a_sampler, a_uv, [&](int x, int y) { return fetch(a_sampler, x, y); });
}

// An image with the sampler it is read through: what Vulkan calls a combined image sampler.
// A std::vector<Texture2D<T>> member (a material's textures, one sampler each) becomes an array of
// textures on the GPU, indexed per thread: m_textures[id].sample(uv). T is float4 or float.
template <typename T>
class Texture2D
{
public:
  Texture2D() = default;
  explicit Texture2D(Image2D<T> a_image, const Sampler& a_sampler = Sampler())
      : m_image(std::move(a_image)), m_sampler(a_sampler)
  {
  }

  T        sample(float2 a_uv) const { return m_image.sample(m_sampler, a_uv); }
  uint32_t width() const { return m_image.width(); }
  uint32_t height() const { return m_image.height(); }
  const T& operator[](const int2& p) const { return m_image[p]; }  // a texel, as Image2D's

  Image2D<T>&       image() { return m_image; }
  const Image2D<T>& image() const { return m_image; }
  Sampler&          sampler() { return m_sampler; }
  const Sampler&    sampler() const { return m_sampler; }

private:
  Image2D<T> m_image;
  Sampler    m_sampler;
};

// ---- combined image samplers, as kernel_slicer's samples write them ----
// An image of any texel type with its sampler, behind an interface: kernels call sample(uv) on a
// std::shared_ptr<ICombinedImageSampler> or ICombinedImageSampler* member, or on an element of a
// std::vector of them, and get a float4 whatever the image holds. Texels read as Vulkan reads them:
// float4 as is, float as (v, 0, 0, 1), uint32_t as RGBA8 unorm (R in the lowest byte, each channel
// c / 255, and R, G and B then linearized where the image is setSRGB(true)); then filtered as
// Image2D<float4> filters (a BORDER texel is the sampler's borderColor).
struct ICombinedImageSampler
{
  virtual ~ICombinedImageSampler() = default;
  virtual float4 sample(float2 a_uv) const = 0;

  virtual unsigned int width() const  = 0;
  virtual unsigned int height() const = 0;
  virtual unsigned int depth() const  = 0;
  virtual unsigned int bpp() const    = 0;  // bytes per texel
  virtual unsigned int format() const = 0;  // the VkFormat of the texels, as a number
  virtual Sampler      sampler() const = 0;
  virtual const void*  data() const    = 0;
};

namespace detail
{
inline float srgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }
inline float4 texelAsFloat4(const float4& t, bool) { return t; }
inline float4 texelAsFloat4(float t, bool) { return float4(t, 0.0f, 0.0f, 1.0f); }
inline float4 texelAsFloat4(uint32_t t, bool a_srgb)
{
  float4 c(float(t & 0xFFu) / 255.0f, float((t >> 8) & 0xFFu) / 255.0f, float((t >> 16) & 0xFFu) / 255.0f, float(t >> 24) / 255.0f);
  if (a_srgb)  // colour channels only, as the GPU's sRGB formats
    c = float4(srgbToLinear(c.x), srgbToLinear(c.y), srgbToLinear(c.z), c.w);
  return c;
}
// VkFormat numbers of the texel types (VK_FORMAT_R8G8B8A8_UNORM or _SRGB, R32_SFLOAT, R32G32B32A32_SFLOAT).
inline unsigned int formatOf(const uint32_t*, bool a_srgb) { return a_srgb ? 43u : 37u; }
inline unsigned int formatOf(const float*, bool) { return 100u; }
inline unsigned int formatOf(const float4*, bool) { return 109u; }

// What MakeCombinedTexture2D makes: the only combined image samplers whose texels TexturesOf can
// hand to a GPU knowing it samples them as sample() does.
struct CombinedTexels : ICombinedImageSampler
{
  virtual Texture2D<float4> textureAsFloat4() const = 0;
};

template <typename T>
struct CombinedTexture2D final : CombinedTexels
{
  CombinedTexture2D(std::shared_ptr<Image2D<T>> a_image, const Sampler& a_sampler) : image(std::move(a_image)), samplerState(a_sampler) {}

  float4 sample(float2 a_uv) const override
  {
    if (!image)
      return float4(0.0f);
    return filterTexels<float4>(image->width(), image->height(), samplerState, a_uv, [&](int x, int y) { return fetch(x, y); });
  }
  unsigned int width() const override { return image ? image->width() : 0u; }
  unsigned int height() const override { return image ? image->height() : 0u; }
  unsigned int depth() const override { return 1u; }
  unsigned int bpp() const override { return unsigned(sizeof(T)); }
  unsigned int format() const override { return formatOf(static_cast<const T*>(nullptr), image && image->srgb()); }
  Sampler      sampler() const override { return samplerState; }
  const void*  data() const override { return image ? image->data() : nullptr; }

  Texture2D<float4> textureAsFloat4() const override
  {
    Image2D<float4> texels(width(), height());
    for (uint32_t y = 0; y < height(); y++)
      for (uint32_t x = 0; x < width(); x++)
        texels.at(int(x), int(y)) = texelAsFloat4(image->at(int(x), int(y)), image->srgb());
    return Texture2D<float4>(std::move(texels), samplerState);
  }

  std::shared_ptr<Image2D<T>> image;
  Sampler                     samplerState;

private:
  float4 fetch(int x, int y) const
  {
    const int xi = addressTexel(x, int(image->width()), samplerState.addressU);
    const int yi = addressTexel(y, int(image->height()), samplerState.addressV);
    if (xi < 0 || yi < 0)
      return samplerState.borderColor;
    return texelAsFloat4(image->at(xi, yi), image->srgb());
  }
};
} // namespace detail

// The image (shared, not copied: later changes to its texels are seen) read through the sampler.
// T is float4, float or uint32_t.
template <typename T>
std::shared_ptr<ICombinedImageSampler> MakeCombinedTexture2D(std::shared_ptr<Image2D<T>> a_image, Sampler a_sampler)
{
  return std::make_shared<detail::CombinedTexture2D<T>>(std::move(a_image), a_sampler);
}

// The textures a GPU samples for combined image samplers, as Texture2D<float4>s whose sample() gives
// each one's sample() bit for bit (what the generated classes upload). A null pointer gives an empty
// texture. Throws std::invalid_argument for an ICombinedImageSampler that MakeCombinedTexture2D did
// not make: its sample() may compute anything, so no texels stand for it.
inline Texture2D<float4> TextureOf(const ICombinedImageSampler* a_sampler)
{
  if (a_sampler == nullptr)
    return Texture2D<float4>();
  auto* texels = dynamic_cast<const detail::CombinedTexels*>(a_sampler);
  if (texels == nullptr)
    throw std::invalid_argument("LiteImage: an ICombinedImageSampler not made by MakeCombinedTexture2D cannot be sampled on the GPU "
                                "(its sample() is the class's own code); make it with MakeCombinedTexture2D(image, sampler)");
  return texels->textureAsFloat4();
}
inline const ICombinedImageSampler* heldSampler(const ICombinedImageSampler* a_sampler) { return a_sampler; }
template <typename P>
const ICombinedImageSampler* heldSampler(const std::shared_ptr<P>& a_sampler) { return a_sampler.get(); }
template <typename P>
const ICombinedImageSampler* heldSampler(const std::unique_ptr<P>& a_sampler) { return a_sampler.get(); }

// One texture per element of a vector of pointers, or one for a single pointer.
template <typename P>
std::vector<Texture2D<float4>> TexturesOf(const std::vector<P>& a_samplers)
{
  std::vector<Texture2D<float4>> textures;
  textures.reserve(a_samplers.size());
  for (const auto& p : a_samplers)
    textures.push_back(TextureOf(heldSampler(p)));
  return textures;
}
template <typename P>
std::vector<Texture2D<float4>> TexturesOf(const P& a_sampler) { return {TextureOf(heldSampler(a_sampler))}; }

// ---- image file IO (OpenImageIO) ----
// Float data is written as-is to float formats (.exr, .hdr, .pfm, .tif/.tiff). Other formats
// (.png, .jpg, .ppm, ...) are 8-bit: values are clamped to [0,1] and quantized, WITHOUT any gamma
// (sRGB) conversion; loading 8-bit files likewise returns value/255 without linearization.
// Formats without alpha (.hdr, .pfm, .jpg, .ppm, ...) drop alpha; loaded images without alpha get
// alpha = 1, grayscale files are replicated to RGB. Grayscale (float) images load the first channel.
// Image2D<uint32_t> is packed RGBA8, R in the lowest byte.
// All functions return false and print a message to stderr on failure; they never throw.
bool LoadImage(const char* a_path, Image2D<float4>& a_out);
bool LoadImage(const char* a_path, Image2D<float>& a_out);
bool LoadImage(const char* a_path, Image2D<uint32_t>& a_out);
bool SaveImage(const char* a_path, const Image2D<float4>& a_img);
bool SaveImage(const char* a_path, const Image2D<float>& a_img);
bool SaveImage(const char* a_path, const Image2D<uint32_t>& a_img);

// kernel_slicer's spelling: w x h packed RGBA8 pixels (R in the lowest byte), top row first, saved
// as a 24-bit BMP file (alpha dropped). Returns false and prints a message on failure.
bool SaveBMP(const char* a_path, const unsigned int* a_pixels, int a_width, int a_height);
// And its reading: any image file as packed RGBA8 pixels (empty, with a message, on failure).
std::vector<unsigned int> LoadBMP(const char* a_path, int* a_width, int* a_height);

} // namespace LiteImage
