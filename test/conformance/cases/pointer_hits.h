// A virtual method that reports through a pointer, as C-style code and kernel_slicer's samples write
// it (Intersect(..., CRT_Hit* pHit, ...)): each shape updates *hit where it is nearer, and the kernel
// passes &hit of its local for every shape, then reads what the shapes left there.
#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <memory>
#include <vector>
using namespace LiteMath;

struct ShapeHit
{
  float t;
  uint32_t shape;
};

struct IShape
{
  virtual ~IShape() = default;
  virtual void Intersect(float3 org, float3 dir, uint32_t id, ShapeHit* hit) const = 0;
  virtual float Area() const = 0;
};

struct Ground : public IShape
{
  float height = 0.0f;
  void Intersect(float3 org, float3 dir, uint32_t id, ShapeHit* hit) const override;
  float Area() const override { return 1e6f; }
};

struct Ball : public IShape
{
  float4 sphere;  // center, radius
  void Intersect(float3 org, float3 dir, uint32_t id, ShapeHit* hit) const override;
  float Area() const override { return 4.0f * 3.14159265f * sphere.w * sphere.w; }
};

class PointerHits
{
public:
  PointerHits();
  virtual void Trace(uint32_t n, const float4* a_dirs [[size("n")]], float4* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}
  std::vector<std::shared_ptr<IShape>> m_shapes;

protected:
  void kernel1D_Trace(uint32_t n, const float4* a_dirs, float4* a_out);
  float3 m_eye;
};
