// A plain C++ path tracer over spheres, written the way the paper's path tracers are (section 4.4):
// the control function Render loops over pixels, and per pixel calls several kernels that pass the
// path's state along in local variables. CrossRT runs that loop on the GPU either as one megakernel
// or as one dispatch per kernel call (wavefront), from this same class.
#pragma once
#include "LiteMath.h"

#include <cstdint>
#include <vector>

using LiteMath::float4;

struct Sphere
{
  float4 centerRadius;  // xyz: center, w: radius
  float4 color;         // rgb: albedo (or emission of a light), w: material (0 diffuse, 1 mirror, 2 light)
};

// The nearest hit of a path's ray.
struct SphereHit
{
  float4 position;  // xyz: the hit point, w: 1 when the ray hit a sphere, 0 when it left the scene
  float4 normal;    // xyz: the outward normal there
  int sphere;       // index into m_spheres
};

class SpherePaths
{
public:
  SpherePaths();
  virtual ~SpherePaths() = default;

  // out_color[y * width + x]: the average of `samples` paths through pixel (x, y), each at most
  // m_maxDepth bounces long.
  virtual void Render(uint32_t width, uint32_t height, int samples, [[crossrt::size("width * height")]] float4* out_color);

  virtual void CommitDeviceData() {}
  virtual void GetExecutionTime(const char* a_funcName, float a_out[4]);

  std::vector<Sphere> m_spheres;
  int m_maxDepth = 4;

protected:
  void kernel_InitEyeRay(uint32_t tidX, uint32_t tidY, uint32_t width, uint32_t height, int sample, float4* rayPos, float4* rayDir, float4* throughput);
  void kernel_RayTrace(uint32_t tidX, uint32_t tidY, const float4* rayPos, const float4* rayDir, const float4* throughput, SphereHit* hit);
  void kernel_NextBounce(uint32_t tidX, uint32_t tidY, uint32_t width, int sample, int bounce, const SphereHit* hit, float4* rayPos, float4* rayDir,
                         float4* throughput, float4* color);
  void kernel_Contribute(uint32_t tidX, uint32_t tidY, uint32_t width, int samples, const float4* color, float4* out_color);

  float4 m_cameraPos;
  float m_tanHalfFov = 0.5f;
  float m_timeMs = 0.0f;
};
