// Analytic signed distance functions as a virtual hierarchy (sphere, box, rounded box, torus, and
// the Mandelbulb fractal's distance estimator), the input of the grid, SVS and SBS builders and of
// sphere tracing. Distances are negative inside. The Mandelbulb's estimate is a lower bound of the
// true distance, which is what the builders and sphere tracing need. Each class holds plain data
// (scalars and LiteMath vectors), so a translated class can call them in its kernels through a
// std::vector<std::shared_ptr<ISdf>> (test/conformance/cases/analytic_sdf.cpp).
#pragma once
#include "LiteMath.h"

#include <cmath>

namespace litesdf {

using LiteMath::float3;

class ISdf {
public:
  virtual ~ISdf() = default;
  virtual float Distance(float3 p) const = 0;
  // |Distance(p)|, or a lower bound of it: all the builders' subdivision needs. A field whose sign
  // costs more than its magnitude (SdfMesh's winding number) overrides it.
  virtual float UnsignedDistance(float3 p) const { return std::fabs(Distance(p)); }
};

class SdfSphere : public ISdf {
public:
  SdfSphere(float3 center, float radius) : m_center(center), m_radius(radius) {}
  float Distance(float3 p) const override { return LiteMath::length(p - m_center) - m_radius; }

private:
  float3 m_center;
  float m_radius;
};

// The distance from p to the box [-halfSize, halfSize] (p relative to the box's centre).
inline float BoxDistance(float3 p, float3 halfSize) {
  const float3 q = LiteMath::abs(p) - halfSize;
  const float3 outside = LiteMath::max(q, float3(0.0f, 0.0f, 0.0f));
  return LiteMath::length(outside) + std::fmin(std::fmax(q.x, std::fmax(q.y, q.z)), 0.0f);
}

class SdfBox : public ISdf {
public:
  SdfBox(float3 center, float3 halfSize) : m_center(center), m_halfSize(halfSize) {}
  float Distance(float3 p) const override { return BoxDistance(p - m_center, m_halfSize); }

private:
  float3 m_center, m_halfSize;
};

// A box whose edges and corners are rounded with `radius` (its half size includes the rounding).
class SdfRoundedBox : public ISdf {
public:
  SdfRoundedBox(float3 center, float3 halfSize, float radius)
      : m_center(center), m_innerHalfSize(halfSize - float3(radius, radius, radius)), m_radius(radius) {}
  float Distance(float3 p) const override { return BoxDistance(p - m_center, m_innerHalfSize) - m_radius; }

private:
  float3 m_center, m_innerHalfSize;
  float m_radius;
};

// A torus around the y axis: `major` from the centre to the tube's centre, `minor` the tube's radius.
class SdfTorus : public ISdf {
public:
  SdfTorus(float3 center, float major, float minor) : m_center(center), m_major(major), m_minor(minor) {}
  float Distance(float3 p) const override {
    const float3 d = p - m_center;
    const float ring = std::sqrt(d.x * d.x + d.z * d.z) - m_major;
    return std::sqrt(ring * ring + d.y * d.y) - m_minor;
  }

private:
  float3 m_center;
  float m_major, m_minor;
};

// The Mandelbulb of power `power` scaled by `scale` around `center`: the distance estimator
// 0.5 log(r) r / dr of its escape-time iteration.
class SdfMandelbulb : public ISdf {
public:
  SdfMandelbulb(float3 center, float scale, float power = 8.0f, int iterations = 12)
      : m_center(center), m_scale(scale), m_power(power), m_iterations(iterations) {}
  float Distance(float3 p) const override {
    const float3 c = (p - m_center) / m_scale;
    float3 z = c;
    float dr = 1.0f, r = LiteMath::length(z);
    for (int i = 0; i < m_iterations && r < 2.0f && r > 0.0f; ++i) {
      const float theta = std::acos(LiteMath::clamp(z.z / r, -1.0f, 1.0f)) * m_power;
      const float phi = std::atan2(z.y, z.x) * m_power;
      dr = std::pow(r, m_power - 1.0f) * m_power * dr + 1.0f;
      const float zr = std::pow(r, m_power);
      z = zr * float3(std::sin(theta) * std::cos(phi), std::sin(phi) * std::sin(theta), std::cos(theta)) + c;
      r = LiteMath::length(z);
    }
    if (r == 0.0f) return -m_scale;  // the centre: inside
    return 0.5f * std::log(r) * r / dr * m_scale;
  }

private:
  float3 m_center;
  float m_scale, m_power;
  int m_iterations;
};

}  // namespace litesdf
