// Image file IO for LiteImage through OpenImageIO. See Image2D.h for the format conventions.
#include "Image2D.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <exception>
#include <string>

namespace LiteImage
{
namespace
{
// A decoded file: interleaved channels, top row first.
template <typename C>
struct RawImage
{
  int            width = 0, height = 0, channels = 0;
  std::vector<C> pixels;
};

std::string lowerExtension(const char* a_path)
{
  const std::string path(a_path);
  const size_t      dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find_first_of("/\\", dot) != std::string::npos)
    return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

// Formats that store floats: linear data is written without quantization.
bool isFloatFormat(const std::string& ext)
{
  return ext == "exr" || ext == "hdr" || ext == "pfm" || ext == "tif" || ext == "tiff";
}
// Formats that can keep an alpha channel; others get RGB only.
bool hasAlpha(const std::string& ext)
{
  return ext == "exr" || ext == "png" || ext == "tif" || ext == "tiff" || ext == "tga" || ext == "webp";
}
// Radiance HDR is RGB-only, so grayscale data has to be replicated there.
bool supportsGray(const std::string& ext) { return ext != "hdr"; }

uint8_t quantize8(float v)
{
  if (!(v > 0.0f)) // also maps NaN to 0
    return 0;
  if (v >= 1.0f)
    return 255;
  return uint8_t(v * 255.0f + 0.5f);
}

template <typename C>
bool readFile(const char* a_path, OIIO::TypeDesc a_type, RawImage<C>& a_raw)
{
  if (a_path == nullptr)
  {
    std::fprintf(stderr, "[LiteImage] LoadImage: null path\n");
    return false;
  }
  try
  {
    // Keep alpha unassociated (straight) as stored in PNG etc.: OIIO would premultiply otherwise.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(a_path, &config);
    if (!in)
    {
      std::fprintf(stderr, "[LiteImage] LoadImage: cannot open '%s': %s\n", a_path, OIIO::geterror().c_str());
      return false;
    }
    const OIIO::ImageSpec& spec = in->spec();
    a_raw.width    = spec.width;
    a_raw.height   = spec.height;
    a_raw.channels = spec.nchannels;
    if (a_raw.width <= 0 || a_raw.height <= 0 || a_raw.channels <= 0)
    {
      std::fprintf(stderr, "[LiteImage] LoadImage: '%s' has invalid size %dx%dx%d\n", a_path, a_raw.width,
                   a_raw.height, a_raw.channels);
      return false;
    }
    a_raw.pixels.resize(size_t(a_raw.width) * a_raw.height * a_raw.channels);
    if (!in->read_image(0, 0, 0, a_raw.channels, a_type, a_raw.pixels.data()))
    {
      std::fprintf(stderr, "[LiteImage] LoadImage: cannot read '%s': %s\n", a_path, in->geterror().c_str());
      return false;
    }
    in->close();
    return true;
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "[LiteImage] LoadImage: '%s': %s\n", a_path, e.what());
    return false;
  }
}

// OIIO 2.4 reads PFM but has no PFM writer, so PFM is written here (1 or 3 float channels).
bool writePFM(const char* a_path, int a_width, int a_height, int a_channels, const float* a_data)
{
  std::FILE* f = std::fopen(a_path, "wb");
  if (f == nullptr)
  {
    std::fprintf(stderr, "[LiteImage] SaveImage: cannot create '%s'\n", a_path);
    return false;
  }
  // Header: "PF" = RGB, "Pf" = gray; the scale's sign gives the byte order (negative = little-endian).
  // Rows go bottom to top.
  const uint16_t probe  = 1;
  const bool     little = *reinterpret_cast<const uint8_t*>(&probe) == 1;
  bool ok = std::fprintf(f, "%s\n%d %d\n%s\n", a_channels == 1 ? "Pf" : "PF", a_width, a_height, little ? "-1.0" : "1.0") > 0;
  const size_t rowSize = size_t(a_width) * a_channels;
  for (int y = a_height - 1; y >= 0 && ok; y--)
    ok = std::fwrite(a_data + size_t(y) * rowSize, sizeof(float), rowSize, f) == rowSize;
  ok = (std::fclose(f) == 0) && ok;
  if (!ok)
    std::fprintf(stderr, "[LiteImage] SaveImage: cannot write '%s'\n", a_path);
  return ok;
}

// Written in the format the file name's extension names, or in `a_format` ("bmp") when given.
bool writeFile(const char* a_path, int a_width, int a_height, int a_channels, OIIO::TypeDesc a_type,
               const void* a_data, const char* a_format = nullptr)
{
  if (a_path == nullptr)
  {
    std::fprintf(stderr, "[LiteImage] SaveImage: null path\n");
    return false;
  }
  if (a_width <= 0 || a_height <= 0)
  {
    std::fprintf(stderr, "[LiteImage] SaveImage: '%s': image is empty (%dx%d)\n", a_path, a_width, a_height);
    return false;
  }
  if (a_format == nullptr && lowerExtension(a_path) == "pfm" && a_type == OIIO::TypeDesc::FLOAT)
    return writePFM(a_path, a_width, a_height, a_channels, static_cast<const float*>(a_data));
  try
  {
    auto out = OIIO::ImageOutput::create(a_format != nullptr ? a_format : a_path);
    if (!out)
    {
      std::fprintf(stderr, "[LiteImage] SaveImage: no writer for '%s': %s\n", a_path, OIIO::geterror().c_str());
      return false;
    }
    OIIO::ImageSpec spec(a_width, a_height, a_channels, a_type);
    spec.attribute("oiio:UnassociatedAlpha", 1); // our data is straight alpha: do not un-premultiply

    if (!out->open(a_path, spec))
    {
      std::fprintf(stderr, "[LiteImage] SaveImage: cannot create '%s': %s\n", a_path, out->geterror().c_str());
      return false;
    }
    if (!out->write_image(a_type, a_data) || !out->close())
    {
      std::fprintf(stderr, "[LiteImage] SaveImage: cannot write '%s': %s\n", a_path, out->geterror().c_str());
      return false;
    }
    return true;
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "[LiteImage] SaveImage: '%s': %s\n", a_path, e.what());
    return false;
  }
}

// Expands 1..4+ file channels to RGBA (gray -> RGB, missing alpha -> one).
template <typename C>
void toRGBA(const C* px, int nch, C one, C rgba[4])
{
  if (nch <= 2)
  {
    rgba[0] = rgba[1] = rgba[2] = px[0];
    rgba[3] = nch == 2 ? px[1] : one;
  }
  else
  {
    rgba[0] = px[0];
    rgba[1] = px[1];
    rgba[2] = px[2];
    rgba[3] = nch >= 4 ? px[3] : one;
  }
}

} // namespace

// ------------------------------------------------------------------ load
bool LoadImage(const char* a_path, Image2D<float4>& a_out)
{
  RawImage<float> raw;
  if (!readFile(a_path, OIIO::TypeDesc::FLOAT, raw))
    return false;
  a_out.resize(uint32_t(raw.width), uint32_t(raw.height));
  float4* dst = a_out.data();
  for (size_t i = 0, n = size_t(raw.width) * raw.height; i < n; i++)
  {
    float c[4];
    toRGBA(&raw.pixels[i * raw.channels], raw.channels, 1.0f, c);
    dst[i] = float4(c[0], c[1], c[2], c[3]);
  }
  return true;
}

bool LoadImage(const char* a_path, Image2D<float>& a_out)
{
  RawImage<float> raw;
  if (!readFile(a_path, OIIO::TypeDesc::FLOAT, raw))
    return false;
  a_out.resize(uint32_t(raw.width), uint32_t(raw.height));
  float* dst = a_out.data();
  for (size_t i = 0, n = size_t(raw.width) * raw.height; i < n; i++)
    dst[i] = raw.pixels[i * raw.channels]; // first channel (red or gray)
  return true;
}

bool LoadImage(const char* a_path, Image2D<uint32_t>& a_out)
{
  RawImage<uint8_t> raw;
  if (!readFile(a_path, OIIO::TypeDesc::UINT8, raw))
    return false;
  a_out.resize(uint32_t(raw.width), uint32_t(raw.height));
  uint32_t* dst = a_out.data();
  for (size_t i = 0, n = size_t(raw.width) * raw.height; i < n; i++)
  {
    uint8_t c[4];
    toRGBA(&raw.pixels[i * raw.channels], raw.channels, uint8_t(255), c);
    dst[i] = uint32_t(c[0]) | (uint32_t(c[1]) << 8) | (uint32_t(c[2]) << 16) | (uint32_t(c[3]) << 24);
  }
  return true;
}

// ------------------------------------------------------------------ save
bool SaveImage(const char* a_path, const Image2D<float4>& a_img)
{
  const std::string ext      = a_path ? lowerExtension(a_path) : "";
  const int         channels = hasAlpha(ext) ? 4 : 3;
  const size_t      n        = size_t(a_img.width()) * a_img.height();
  const float4*     src      = a_img.data();
  const int         w = int(a_img.width()), h = int(a_img.height());
  if (isFloatFormat(ext))
  {
    std::vector<float> buf(n * channels);
    for (size_t i = 0; i < n; i++)
      for (int c = 0; c < channels; c++)
        buf[i * channels + c] = src[i][c];
    return writeFile(a_path, w, h, channels, OIIO::TypeDesc::FLOAT, buf.data());
  }
  std::vector<uint8_t> buf(n * channels);
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < channels; c++)
      buf[i * channels + c] = quantize8(src[i][c]);
  return writeFile(a_path, w, h, channels, OIIO::TypeDesc::UINT8, buf.data());
}

bool SaveImage(const char* a_path, const Image2D<float>& a_img)
{
  const std::string ext      = a_path ? lowerExtension(a_path) : "";
  const int         channels = supportsGray(ext) ? 1 : 3;
  const size_t      n        = size_t(a_img.width()) * a_img.height();
  const float*      src      = a_img.data();
  const int         w = int(a_img.width()), h = int(a_img.height());
  if (isFloatFormat(ext))
  {
    std::vector<float> buf(n * channels);
    for (size_t i = 0; i < n; i++)
      for (int c = 0; c < channels; c++)
        buf[i * channels + c] = src[i];
    return writeFile(a_path, w, h, channels, OIIO::TypeDesc::FLOAT, buf.data());
  }
  std::vector<uint8_t> buf(n * channels);
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < channels; c++)
      buf[i * channels + c] = quantize8(src[i]);
  return writeFile(a_path, w, h, channels, OIIO::TypeDesc::UINT8, buf.data());
}

bool SaveImage(const char* a_path, const Image2D<uint32_t>& a_img)
{
  // 8-bit data is written as UINT8; OIIO converts it (as value/255) for float-only formats.
  const std::string ext      = a_path ? lowerExtension(a_path) : "";
  const int         channels = hasAlpha(ext) ? 4 : 3;
  const size_t      n        = size_t(a_img.width()) * a_img.height();
  const uint32_t*   src      = a_img.data();
  std::vector<uint8_t> buf(n * channels);
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < channels; c++)
      buf[i * channels + c] = uint8_t((src[i] >> (8 * c)) & 0xFFu);
  return writeFile(a_path, int(a_img.width()), int(a_img.height()), channels, OIIO::TypeDesc::UINT8, buf.data());
}

bool SaveBMP(const char* a_path, const unsigned int* a_pixels, int a_width, int a_height)
{
  if (a_pixels == nullptr && a_width > 0 && a_height > 0)
  {
    std::fprintf(stderr, "[LiteImage] SaveBMP: '%s': no pixels\n", a_path ? a_path : "(null)");
    return false;
  }
  const size_t         n = a_width > 0 && a_height > 0 ? size_t(a_width) * size_t(a_height) : 0;
  std::vector<uint8_t> rgb(n * 3);
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < 3; c++)
      rgb[i * 3 + c] = uint8_t((a_pixels[i] >> (8 * c)) & 0xFFu);
  return writeFile(a_path, a_width, a_height, 3, OIIO::TypeDesc::UINT8, rgb.data(), "bmp");
}

std::vector<unsigned int> LoadBMP(const char* a_path, int* a_width, int* a_height)
{
  Image2D<uint32_t> image;
  const bool        ok = LoadImage(a_path, image);
  if (a_width != nullptr)
    *a_width = ok ? int(image.width()) : 0;
  if (a_height != nullptr)
    *a_height = ok ? int(image.height()) : 0;
  if (!ok)
    return {};
  return std::vector<unsigned int>(image.data(), image.data() + size_t(image.width()) * image.height());
}

} // namespace LiteImage
