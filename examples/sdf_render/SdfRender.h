// A renderer of signed distance fields in plain C++: camera rays through ISceneObject, which holds
// the fields (AddGeom_SdfGrid, AddGeom_SdfSVS, AddGeom_SdfSBS) and any meshes beside them; shading
// by the surface normal the hit reports and by ambient occlusion (any-hit rays), packed RGBA8 pixels
// out. It never names an implementation: CrossRT derives SdfRender_CPU (all cores) and
// SdfRender_Vulkan, which runs BVHScene's traversal, SDF leaves included, on the GPU by composition
// (COMPOSE ISceneObject=BVHScene in CMakeLists.txt).
#pragma once
#include "CrossRT.h"
#include "LiteMath.h"

#include <cstdint>
#include <memory>

using LiteMath::float3;
using LiteMath::float4;

class SdfRender
{
public:
  SdfRender(int width, int height) : m_width(width), m_height(height) {}
  virtual ~SdfRender() = default;

  // The scene to trace (committed).
  void SetScene(std::shared_ptr<ISceneObject> scene) { m_pAccelStruct = std::move(scene); }
  // A pinhole camera at eye looking at target, fovY in degrees.
  void SetCamera(float3 eye, float3 target, float fovY);
  // Ambient occlusion: rays per hit (0 = off) and their length.
  void SetOcclusion(int samples, float distance);

  // Renders width x height pixels, packed RGBA8, row 0 at the top; depth[i] is the hit's t, or -1.
  virtual void Render([[crossrt::size("m_width * m_height")]] uint32_t* pixels, [[crossrt::size("m_width * m_height")]] float* depth);

  virtual void CommitDeviceData() {}
  virtual void GetExecutionTime(const char* a_funcName, float a_out[4])
  {
    (void)a_funcName;
    for (int i = 0; i < 4; ++i)
      a_out[i] = 0.0f;
  }

protected:
  void kernel2D_Render(uint32_t* pixels, float* depth, int width, int height);
  // The colour of a hit seen along dir (RGB in [0, 1]); pixel seeds the occlusion rays.
  float3 Shade(const CRT_Hit& hit, float3 org, float3 dir, uint32_t pixel) const;

  std::shared_ptr<ISceneObject> m_pAccelStruct;
  int m_width, m_height;
  int m_aoSamples = 0;
  float m_aoDistance = 0.3f;
  float3 m_eye = float3(0.0f, 0.0f, -3.0f), m_forward = float3(0.0f, 0.0f, 1.0f);
  float3 m_right = float3(1.0f, 0.0f, 0.0f), m_up = float3(0.0f, 1.0f, 0.0f);
};
