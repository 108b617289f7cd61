// A renderer of signed distance fields in plain C++: camera rays against a sparse voxel set through
// a BVH over its voxels (litesdf), shaded by the surface normal, packed RGBA8 pixels out. CrossRT
// derives SdfRender_CPU from it, which renders on all cores.
#pragma once
#include "LiteMath.h"
#include "SdfBVH.h"

#include <cstdint>
#include <vector>

using LiteMath::float3;

class SdfRender
{
public:
  SdfRender(int width, int height) : m_width(width), m_height(height) {}
  virtual ~SdfRender() = default;

  // The field to render (copied) and the BVH over its voxels; Newton iterations per voxel.
  void SetField(const litesdf::SdfSVS& svs, int newtonIterations);
  // A pinhole camera at eye looking at target, fovY in degrees.
  void SetCamera(float3 eye, float3 target, float fovY);

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

  int m_width, m_height;
  int m_newtonIterations = 4;
  float3 m_eye = float3(0.0f, 0.0f, -3.0f), m_forward = float3(0.0f, 0.0f, 1.0f);
  float3 m_right = float3(1.0f, 0.0f, 0.0f), m_up = float3(0.0f, 1.0f, 0.0f);
  litesdf::SdfSVS m_svs;
  BVHTree m_bvh;
};
