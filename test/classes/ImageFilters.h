// Textures: Image2D members whose texels kernels load and store (storage images on the GPU) and
// sample through LiteImage::Sampler members (textures and samplers), with nearest and bilinear
// filtering and every address mode (test/equivalence/test_images.cpp).
#pragma once
#include "Image2D.h"
#include "LiteMath.h"

#include <cstdint>

class ImageFilters
{
public:
  ImageFilters() = default;
  virtual ~ImageFilters() = default;

  // A 3x3 box blur of m_source (edges clamped) into m_blurred, its luminance into m_luminance
  // and, into m_labels, 1 where the luminance exceeds `threshold`. The outputs must have
  // m_source's size.
  virtual void Blur(float threshold);
  // Samples m_source at uv[i] with m_nearest and m_linear, and m_heights with m_heightSampler.
  virtual void Sample(int n, [[crossrt::size("n")]] const LiteMath::float2* uv, [[crossrt::size("n")]] LiteMath::float4* nearest,
                      [[crossrt::size("n")]] LiteMath::float4* linear, [[crossrt::size("n")]] float* heights);
  // m_accumulated += weight * m_source, texel by texel; m_counts += 1.
  virtual void Accumulate(float weight);
  // m_accumulated *= 2, by thread functions called from the control function's loops, which
  // sample the image they store (each thread its own texel, at its centre).
  virtual void Double();
  virtual void CommitDeviceData() {}

  LiteImage::Image2D<LiteMath::float4> m_source, m_blurred, m_accumulated;
  LiteImage::Image2D<float> m_heights, m_luminance;
  LiteImage::Image2D<uint32_t> m_labels, m_counts;
  LiteImage::Sampler m_nearest, m_linear, m_heightSampler;

protected:
  void kernel2D_Blur(float threshold);
  void kernel1D_Sample(int n, const LiteMath::float2* uv, LiteMath::float4* nearest, LiteMath::float4* linear, float* heights);
  void kernel2D_Accumulate(float weight);
  void kernel_Double(int tidX, int tidY);
  // A helper reaching images too: the clamped texel of m_source.
  LiteMath::float4 SourceTexel(int x, int y) const;
};
