// A renderer over litesdf's own analytic shapes (libs/litesdf/SdfAnalytic.h), as a user writes one
// for the paper's course (4.5): the union of a sphere, a box, a rounded box, a torus and a
// Mandelbulb, sphere-traced. The shapes are library classes in a namespace, with private data; the
// coverage is a member reduction zeroed before the kernel and divided by the pixel count after it.
#pragma once
#include "SdfAnalytic.h"

#include <cstdint>
#include <memory>
#include <vector>

class FractalView
{
public:
  FractalView(int width, int height);
  virtual ~FractalView() = default;
  void Add(std::shared_ptr<litesdf::ISdf> shape) { m_shapes.push_back(std::move(shape)); }
  virtual void Render(float* depth [[crossrt::size("m_width * m_height")]]);
  virtual void CommitDeviceData() {}
  float Coverage() const { return m_coverage; }

protected:
  void kernel2D_Render(float* depth, int width, int height);
  float Scene(LiteMath::float3 p) const;
  std::vector<std::shared_ptr<litesdf::ISdf>> m_shapes;
  LiteMath::float3 m_eye, m_forward, m_right, m_up;
  int m_width, m_height;
  float m_coverage = 0.0f;
};
