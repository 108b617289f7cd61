// A primary-ray renderer in plain C++: camera rays, the nearest hit through ISceneObject, shading
// by the surface normal and ambient occlusion (any-hit rays), packed RGBA8 pixels out. It never
// names an implementation, so the same class runs on Embree or on CrossRT's BVHs; its translated
// PrimaryRays_Vulkan runs BVHScene's traversal on the GPU by composition (COMPOSE
// ISceneObject=BVHScene in CMakeLists.txt).
//
// CastRays traces a batch of given rays: it is what tests and benchmarks compare across backends.
#pragma once
#include "CrossRT.h"
#include "LiteMath.h"

#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

using LiteMath::float3;
using LiteMath::float4;

constexpr float kCameraFar = 1e30f;  // tmax of camera rays

// An RGB colour in [0, 1] as RGBA8 (alpha 255), red in the low byte.
inline uint32_t PackRGBA8(float3 c)
{
  const uint32_t r = uint32_t(std::min(std::max(c.x, 0.0f), 1.0f) * 255.0f + 0.5f);
  const uint32_t g = uint32_t(std::min(std::max(c.y, 0.0f), 1.0f) * 255.0f + 0.5f);
  const uint32_t b = uint32_t(std::min(std::max(c.z, 0.0f), 1.0f) * 255.0f + 0.5f);
  return r | (g << 8) | (b << 16) | 0xFF000000u;
}

class PrimaryRays
{
public:
  PrimaryRays(int width, int height);
  virtual ~PrimaryRays() = default;

  // The scene to trace, and the mesh it holds as instance 0 (for the shading normals): positions
  // xyz per vertex, three indices per triangle.
  void SetScene(std::shared_ptr<ISceneObject> scene, const std::vector<float>& positions, const std::vector<uint32_t>& indices);
  // A pinhole camera at eye looking at target, fovY in degrees.
  void SetCamera(float3 eye, float3 target, float3 up, float fovY);
  // Ambient occlusion: rays per hit (0 = off) and their length.
  void SetOcclusion(int samples, float distance);

  // Renders width x height pixels, packed RGBA8, row 0 at the top.
  virtual void Render([[crossrt::size("m_width * m_height")]] uint32_t* pixels);
  // hits[i] = the nearest hit of ray i (origin xyz + tmin, direction xyz + tmax).
  virtual void CastRays([[crossrt::size("n")]] const float4* posAndNear, [[crossrt::size("n")]] const float4* dirAndFar,
                        [[crossrt::size("n")]] CRT_Hit* hits, int n);

  virtual void CommitDeviceData() {}
  virtual void GetExecutionTime(const char* a_funcName, float a_out[4])
  {
    (void)a_funcName;
    for (int i = 0; i < 4; ++i)
      a_out[i] = 0.0f;
  }

  int Width() const { return m_width; }
  int Height() const { return m_height; }

protected:
  void kernel2D_Render(uint32_t* pixels, int width, int height);
  void kernel1D_CastRays(const float4* posAndNear, const float4* dirAndFar, CRT_Hit* hits, int n);

  // The shade of a hit (RGB in [0, 1]) seen along direction dir; pixel seeds the occlusion rays.
  float3 Shade(const CRT_Hit& hit, float3 org, float3 dir, uint32_t pixel) const;

  std::shared_ptr<ISceneObject> m_pAccelStruct;
  std::vector<float4> m_vertices;   // xyz, for normals
  std::vector<uint32_t> m_indices;  // three per triangle

  float4 m_eye = float4(0.0f, 0.0f, 3.0f, 0.0f);
  float4 m_forward = float4(0.0f, 0.0f, -1.0f, 0.0f);  // scaled by the focal length
  float4 m_right = float4(1.0f, 0.0f, 0.0f, 0.0f);     // scaled by tan(fovY / 2) * aspect
  float4 m_up = float4(0.0f, 1.0f, 0.0f, 0.0f);        // scaled by tan(fovY / 2)
  int m_width;
  int m_height;
  int m_aoSamples = 4;
  float m_aoDistance = 0.2f;
};
