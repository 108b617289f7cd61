// A plain C++ bloom filter: bright pixels are extracted, blurred with a separable Gaussian, and
// added back. CrossRT derives Bloom_Vulkan and Bloom_CPU from it.
#pragma once
#include "LiteMath.h"

#include <vector>

using LiteMath::float4;

// Perceived brightness of a linear RGB colour.
inline float Luminance(const float4& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

class Bloom
{
public:
  Bloom(int width, int height, int radius, float sigma);
  virtual ~Bloom() = default;

  // out = in + strength * blur(bright parts of in); images are width*height, row-major.
  virtual void Run(int width, int height,
                   [[crossrt::size("width*height")]] const float4* in,
                   [[crossrt::size("width*height")]] float4* out);

  virtual void CommitDeviceData() {}
  virtual void GetExecutionTime(const char* a_funcName, float a_out[4]) { (void)a_funcName; for (int i = 0; i < 4; ++i) a_out[i] = 0.0f; }

  float m_threshold = 1.0f;
  float m_strength = 0.6f;

protected:
  void kernel2D_ExtractBright(int width, int height, const float4* in, float4* bright);
  void kernel2D_BlurX(int width, int height, const float4* src, float4* dst);
  void kernel2D_BlurYAndAdd(int width, int height, const float4* src, const float4* in, float4* out);

  int m_radius;
  std::vector<float> m_weights;  // 2*radius+1 normalised Gaussian weights
  std::vector<float4> m_bright, m_blurred;
};
