// A user's class: explicit heat diffusion on a grid, plus the total heat as a reduction.
#pragma once
#include "LiteMath.h"
#include <vector>

class Heat
{
public:
  Heat(int w, int h) : m_width(w), m_height(h), m_next(size_t(w) * h) {}
  virtual ~Heat() = default;
  virtual void Diffuse(int steps, [[crossrt::size("m_width * m_height")]] float* grid);
  virtual void CommitDeviceData() {}
  float m_total = 0.0f;

protected:
  void kernel2D_Step(int w, int h, const float* src, float* dst);
  void kernel1D_CopyBack(int n, float* grid);
  int m_width, m_height;
  float m_rate = 0.2f;
  std::vector<float> m_next;
};
