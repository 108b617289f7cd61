// Arrays of textures (combined image samplers): std::vector<LiteImage::Texture2D<T>> members whose
// textures kernels pick per thread, each with its own size and sampler (address modes, filter)
// (test/equivalence/test_texture_arrays.cpp).
#pragma once
#include "Image2D.h"
#include "LiteMath.h"

#include <cstdint>
#include <vector>

class TexturedMaterials
{
public:
  TexturedMaterials() = default;
  virtual ~TexturedMaterials() = default;

  // For hit i: colors[i] = m_albedo[texIds[i] % size].sample(uvs[i]), heights[i] the bump map's
  // sample there plus its width; texels[i] a texel of m_albedo[0] read by index.
  virtual void Shade(int n, [[crossrt::size("n")]] const uint32_t* texIds, [[crossrt::size("n")]] const LiteMath::float2* uvs,
                     [[crossrt::size("n")]] LiteMath::float4* colors, [[crossrt::size("n")]] float* heights,
                     [[crossrt::size("n")]] LiteMath::float4* texels);
  virtual void CommitDeviceData() {}

  std::vector<LiteImage::Texture2D<LiteMath::float4>> m_albedo;
  std::vector<LiteImage::Texture2D<float>> m_bumps;
  // Names the GLSL once gave the functions and buffers of the array m_bumps (issue 52): kernels read
  // them as the members they are.
  float m_bumps_sample = 0.5f, m_bumps_texel = 0.25f, m_bumps_width = 0.125f, m_bumps_info = 0.0625f, m_bumps_texels = 0.03125f;

protected:
  void kernel1D_Shade(int n, const uint32_t* texIds, const LiteMath::float2* uvs, LiteMath::float4* colors, float* heights,
                      LiteMath::float4* texels);
  // A helper reaching the array too.
  LiteMath::float4 Albedo(uint32_t a_texId, LiteMath::float2 a_uv) const;
};
