// A second user class, as people write one: it lives in ray_caster.h / render_passes.cpp (neither
// named after it), traces through ISceneObject, keeps helpers and static functions in the .cpp, and
// sets its statistics up before the pixel loop and finishes them after it.
#pragma once
#include "CrossRT.h"
#include "LiteMath.h"

#include <cstdint>
#include <memory>
#include <vector>

using namespace LiteMath;

class RayCaster
{
public:
  RayCaster(int a_width, int a_height);
  virtual ~RayCaster() {}

  void SetScene(std::shared_ptr<ISceneObject> a_scene) { m_pAccelStruct = a_scene; }
  void SetCamera(float3 a_eye, float a_fovDegrees);

  // Colour (RGBA8) and depth (0 where nothing is hit) per pixel, row 0 at the top.
  virtual void Render(uint32_t* a_color [[size("m_width * m_height")]], float* a_depth [[size("m_width", "m_height")]]);
  // Sorts the depths of the pixels Render hit (ascending) into a_sorted, their count into a_count.
  virtual void SortedDepths(float* a_sorted [[size("m_width * m_height")]], uint32_t* a_count [[size(1)]]);
  virtual void CommitDeviceData() {}

  uint32_t m_hitCount = 0;  // pixels that hit something, in the last Render
  float m_meanDepth = 0.0f; // their mean depth
  float m_maxDepth = 0.0f;

protected:
  void kernel2D_Render(uint32_t* a_color, float* a_depth, int a_width, int a_height);
  void kernel1D_CollectHits(const float* a_depth, int a_count);
  void kernel1D_CopySorted(float* a_sorted, uint32_t* a_count);

  float3 EyeRayDir(int x, int y) const;

  std::shared_ptr<ISceneObject> m_pAccelStruct;
  std::vector<float> m_hitDepths;
  float4 m_eye = float4(0.0f, 0.0f, 3.0f, 0.0f);
  float m_tanHalfFov = 0.5f;
  int m_width, m_height;
};
