// Composition of a user's own interface (not ISceneObject): a sphere tracer marching through an
// ISdf it holds, composed on the GPU with SdfSpheres, whose data is a std::vector and two plain
// members. The test sets the plain members between calls: the GPU must see each new value.
#pragma once
#include "LiteMath.h"

#include <memory>
#include <vector>

struct ISdf
{
  virtual ~ISdf() = default;
  virtual float Distance(LiteMath::float3 p) = 0;
};

class SdfSpheres : public ISdf
{
public:
  float Distance(LiteMath::float3 p) override;

  std::vector<LiteMath::float4> m_spheres;  // centre xyz, radius w
  float m_smoothing = 0.0f;                 // > 0: blend neighbouring spheres (polynomial smooth minimum)
  int m_count = 0;                          // spheres in use (a prefix of m_spheres)
};

class SphereTracer
{
public:
  SphereTracer() = default;
  virtual ~SphereTracer() = default;
  void SetShape(std::shared_ptr<ISdf> shape) { m_shape = std::move(shape); }

  // depth[i]: distance along -z from origins[i].xyz to the surface, or -1 when nothing is hit.
  virtual void Trace(int n, [[crossrt::size("n")]] const LiteMath::float4* origins, [[crossrt::size("n")]] float* depth);

  virtual void CommitDeviceData() {}
  virtual void GetExecutionTime(const char*, float a_out[4])
  {
    for (int i = 0; i < 4; ++i)
      a_out[i] = 0.0f;
  }

protected:
  void kernel1D_Trace(int n, const LiteMath::float4* origins, float* depth);
  std::shared_ptr<ISdf> m_shape;
};
