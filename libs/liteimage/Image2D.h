// LiteImage: a minimal 2D image container with a Vulkan-like sampler and image file IO.
#pragma once

#include "LiteMath.h"

#include <cstdint>
#include <utility>
#include <vector>

namespace LiteImage
{
using LiteMath::float2;
using LiteMath::float4;
using LiteMath::int2;

// Mirrors the relevant part of VkSamplerCreateInfo. Defaults: WRAP (repeat) + NEAREST.
struct Sampler
{
  enum class AddressMode { WRAP, MIRROR, CLAMP, BORDER };
  enum class Filter { NEAREST, LINEAR };

  AddressMode addressU    = AddressMode::WRAP;
  AddressMode addressV    = AddressMode::WRAP;
  Filter      filter      = Filter::NEAREST;
  float4      borderColor = float4(0.0f); // returned for texels outside the image in BORDER mode
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
};

template <typename T>
T Image2D<T>::sample(const Sampler& a_sampler, float2 a_uv) const
{
  if (m_width == 0 || m_height == 0)
    return T();

  const float x = detail::sanitizeCoord(a_uv.x * float(m_width));
  const float y = detail::sanitizeCoord(a_uv.y * float(m_height));

  if (a_sampler.filter == Sampler::Filter::NEAREST)
    return fetch(a_sampler, int(std::floor(x)), int(std::floor(y)));

  // Bilinear: shift by half a texel so that integer positions are texel centers.
  const float fx = x - 0.5f, fy = y - 0.5f;
  const float x0 = std::floor(fx), y0 = std::floor(fy);
  const float tx = fx - x0, ty = fy - y0;
  const int   ix = int(x0), iy = int(y0);

  const T t00 = fetch(a_sampler, ix, iy);
  const T t10 = fetch(a_sampler, ix + 1, iy);
  const T t01 = fetch(a_sampler, ix, iy + 1);
  const T t11 = fetch(a_sampler, ix + 1, iy + 1);
  const T top    = t00 * (1.0f - tx) + t10 * tx;
  const T bottom = t01 * (1.0f - tx) + t11 * tx;
  return top * (1.0f - ty) + bottom * ty;
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

} // namespace LiteImage
