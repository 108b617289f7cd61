// Intersection functions inside composed code (paper 3.10, listing 2): ShapeTracer holds an IScene,
// composed on the GPU with ShapeScene, whose traversal calls a virtual Intersect for each primitive
// it reaches, in two vectors (shapes and lights). Three shape classes with data of different sizes
// implement it; on the GPU the call becomes a switch over the shape's class, or at level 3 an
// intersection shader per class (test/equivalence/test_composition.cpp).
#pragma once
#include "LiteMath.h"

#include <cstdint>
#include <memory>
#include <vector>

// The nearest hit so far: its distance along the ray (the ray's far end while nothing is hit),
// the shape's index (~0u for none) and the hit point's normal.
struct ShapeHit
{
  float t;
  uint32_t shape;
  float nx, ny, nz;
  float pad0, pad1, pad2;  // 32 bytes, as a GPU buffer holds it
};

struct IShape
{
  virtual ~IShape() = default;
  // Updates hit when the ray (pos + t * dir, t in [near, hit.t)) meets the shape nearer.
  virtual void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, uint32_t shapeId, ShapeHit& hit) const = 0;
  virtual LiteMath::float4 BoxMin() const = 0;  // host only: the scene's leaf boxes
  virtual LiteMath::float4 BoxMax() const = 0;
};

class Sphere : public IShape  // 16 bytes of data
{
public:
  Sphere(LiteMath::float3 c, float r) : centerAndRadius(c.x, c.y, c.z, r) {}
  void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, uint32_t shapeId, ShapeHit& hit) const override;
  LiteMath::float4 BoxMin() const override;
  LiteMath::float4 BoxMax() const override;
  LiteMath::float4 centerAndRadius;
};

class Box : public IShape  // 32 bytes
{
public:
  Box(LiteMath::float3 lo, LiteMath::float3 hi) : boxMin(lo.x, lo.y, lo.z, 0.0f), boxMax(hi.x, hi.y, hi.z, 0.0f) {}
  void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, uint32_t shapeId, ShapeHit& hit) const override;
  LiteMath::float4 BoxMin() const override { return boxMin; }
  LiteMath::float4 BoxMax() const override { return boxMax; }
  LiteMath::float4 boxMin, boxMax;
};

class Disc : public IShape  // 36 bytes (48 with C++'s padding)
{
public:
  Disc(LiteMath::float3 c, LiteMath::float3 n, float r) : center(c.x, c.y, c.z, 0.0f), normal(n.x, n.y, n.z, 0.0f), radius(r) {}
  void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, uint32_t shapeId, ShapeHit& hit) const override;
  LiteMath::float4 BoxMin() const override;
  LiteMath::float4 BoxMax() const override;
  LiteMath::float4 center, normal;  // normal has unit length
  float radius;
};

struct IScene
{
  virtual ~IScene() = default;
  virtual ShapeHit Trace(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) = 0;
};

// The leaves of a scene: one box per shape (min, max), tested before the shape's Intersect. Lights
// are shapes too, kept apart (a renderer samples them): a ray that meets one nearest reports it
// as kLightHit + its index.
class ShapeScene : public IScene
{
public:
  static constexpr uint32_t kLightHit = 0x80000000u;
  void Add(std::shared_ptr<IShape> shape);
  void AddLight(std::shared_ptr<IShape> light);
  ShapeHit Trace(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) override;

  std::vector<std::shared_ptr<IShape>> m_shapes, m_lights;
  std::vector<LiteMath::float4> m_boxes, m_lightBoxes;  // 2 per shape, 2 per light
};

class ShapeTracer
{
public:
  ShapeTracer() = default;
  virtual ~ShapeTracer() = default;
  void SetScene(std::shared_ptr<IScene> scene) { m_scene = std::move(scene); }

  // hits[i]: the nearest shape along the ray from origins[i] in direction dirs[i] (xyz), up to far.
  virtual void Trace(int n, [[crossrt::size("n")]] const LiteMath::float4* origins, [[crossrt::size("n")]] const LiteMath::float4* dirs, float far,
                     [[crossrt::size("n")]] ShapeHit* hits);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Trace(int n, const LiteMath::float4* origins, const LiteMath::float4* dirs, float far, ShapeHit* hits);
  std::shared_ptr<IScene> m_scene;
};
