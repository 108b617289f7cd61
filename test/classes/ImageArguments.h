// Image2D parameters: images a control function is given per call and passes to its kernels,
// which load, store and sample them and read their size, as they do with Image2D members
// (test/equivalence/test_image_arguments.cpp). Kernels are given members through such
// parameters too.
#pragma once
#include "Image2D.h"
#include "LiteMath.h"

#include <cstdint>

class ImageArguments
{
public:
  using Image4 = LiteImage::Image2D<LiteMath::float4>;

  ImageArguments() = default;
  virtual ~ImageArguments() = default;

  // out = gain * the 3x3 box blur of `in` (edges clamped). out must have in's size.
  virtual void Blur(const Image4& in, Image4& out, float gain);
  // heights[i] = field sampled at uv[i] with m_linear; colors[i] = albedo sampled with m_nearest,
  // times albedo's texel count.
  virtual void Sample(const LiteImage::Image2D<float>& field, const Image4& albedo, int n, [[crossrt::size("n")]] const LiteMath::float2* uv,
                      [[crossrt::size("n")]] float* heights, [[crossrt::size("n")]] LiteMath::float4* colors);
  // m_history = mix(m_history, frame, alpha), texel by texel, through a kernel that is given the
  // member as a parameter; then labels = 1 where m_history's luminance exceeds threshold, else 0.
  // frame and labels must have m_history's size.
  virtual void Accumulate(const Image4& frame, float alpha, float threshold, LiteImage::Image2D<uint32_t>& labels);
  // img *= factor in place, one thread per texel (thread functions called from loops).
  virtual void Scale(LiteImage::Image2D<float>& img, float factor);
  virtual void CommitDeviceData() {}

  Image4 m_history;
  LiteImage::Sampler m_nearest, m_linear;

protected:
  void kernel2D_Blur(const Image4& in, Image4& out, float gain);
  void kernel1D_Sample(const LiteImage::Image2D<float>& field, const Image4& albedo, int n, const LiteMath::float2* uv, float* heights,
                       LiteMath::float4* colors);
  void kernel2D_Blend(const Image4& frame, Image4& history, float alpha);
  void kernel2D_Threshold(const Image4& image, LiteImage::Image2D<uint32_t>& labels, float threshold);
  void kernel_Scale(int tidX, int tidY, LiteImage::Image2D<float>& img, float factor);
};
