// kernel_slicer's combined image samplers (LiteImage::ICombinedImageSampler), written as its samples
// write them: a shared_ptr member, a plain pointer member, a std::vector of shared_ptrs and one of
// const pointers, sampled in a kernel and in a helper member function, over images of uint32_t
// (RGBA8), float and float4 (test/equivalence/test_texture_arrays.cpp).
#pragma once
#include "Image2d.h"

#include <memory>
#include <vector>

using LiteImage::ICombinedImageSampler;

class CombinedSamplers
{
public:
  CombinedSamplers();
  virtual ~CombinedSamplers() = default;

  virtual void Run(const int a_width, const int a_height, LiteMath::float4* a_out __attribute__((size("a_width", "a_height"))));

  virtual void CommitDeviceData() {}                                       // overridden by the generated classes
  virtual void GetExecutionTime(const char* /*a_funcName*/, float /*a_out*/[4]) {} // likewise

  std::shared_ptr<ICombinedImageSampler> m_pLogo = nullptr;
  std::shared_ptr<ICombinedImageSampler> m_pMaskStorage = nullptr;  // not read by kernels
  ICombinedImageSampler*                 m_pMask = nullptr;         // a plain pointer, read by kernels
  std::vector<std::shared_ptr<ICombinedImageSampler>> m_textures;
  std::vector<const ICombinedImageSampler*>           m_views;      // m_textures in another order

  // The images behind them, shared: a test changes texels and calls CommitDeviceData().
  std::shared_ptr<LiteImage::Image2D<uint32_t>> m_logoImage;

protected:
  void kernel2D_Run(const int a_width, const int a_height, LiteMath::float4* a_out);
  LiteMath::float4 Tinted(LiteMath::float2 a_uv, int a_id) const { return clamp(m_textures[a_id]->sample(a_uv), 0.0f, 1.0f) * 2.0f; }
};
