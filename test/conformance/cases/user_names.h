// A class whose names are those the generated code used to derive from its names (issue 52): a
// member vector's size and capacity in the class data (m_a_size, m_a_capacity), an image's width
// (m_img_width), the GLSL block of a buffer (a parameter's name + "Buffer"), the class data's block
// (the class's name + "Data"), and the names of the reduction of m_total (its per-thread copy
// m_totalLocal, its workgroup array m_totalShared, its per-group results m_totalPartials, ...).
// Each once collided in the generated code; derived names now carry the reserved prefix crt_.
#pragma once
#include "Image2d.h"
#include "LiteMath.h"

#include <cstdint>
#include <vector>

struct LookalikesData  // the class data's block was named so
{
  float bias;
};

class Lookalikes
{
public:
  explicit Lookalikes(int n);
  virtual ~Lookalikes() = default;
  virtual void Run(int n, [[crossrt::size("n")]] const float* src, [[crossrt::size("n")]] float* srcBuffer);
  virtual void CommitDeviceData() {}

  std::vector<float> m_a;
  uint32_t m_a_size = 7;      // m_a.size() in the class data was m_a_size
  uint32_t m_a_capacity = 9;  // and its capacity m_a_capacity
  LookalikesData m_data{0.25f};
  LiteImage::Image2D<LiteMath::float4> m_img;
  uint32_t m_img_width = 3;  // m_img.width() in the class data was m_img_width
  float m_total = 0.0f;
  float m_totalLocal = 2.0f;  // the reduction of m_total named its parts so
  float m_totalShared = 4.0f;
  float m_totalPartials = 8.0f;
  float m_totalGroup = 16.0f;
  float m_totalSubgroup = 32.0f;

protected:
  void kernel1D_Fill(int n, const float* src, float* srcBuffer);  // src's block was srcBuffer
};
