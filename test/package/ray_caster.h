// A second user class, as people write one: it lives in ray_caster.h / render_passes.cpp (neither
// named after it), traces through ISceneObject, shades through virtual calls, keeps helpers and
// static functions in the .cpp, sets its statistics up before the pixel loop and finishes them
// after it, appends and sorts the hit depths, and scans the hits per row.
#pragma once
#include "CrossRT.h"
#include "LiteMath.h"

#include <cstdint>
#include <memory>
#include <vector>

using namespace LiteMath;

// How an object looks: one implementation per kind, called through the base class.
struct IShade
{
  virtual ~IShade() {}
  virtual float3 Color(float3 a_dir, uint32_t a_prim) const = 0;
};

struct FlatShade : public IShade
{
  float3 albedo = float3(0.8f, 0.3f, 0.2f);
  float3 Color(float3 a_dir, uint32_t a_prim) const override { return albedo * (0.3f + 0.7f * std::abs(a_dir.z)) + 0.0f * float(a_prim); }
};

struct StripeShade : public IShade
{
  float3 even = float3(0.9f, 0.9f, 0.9f);
  float3 odd = float3(0.1f, 0.4f, 0.9f);
  float3 Color(float3 a_dir, uint32_t a_prim) const override { return ((a_prim / 2u) % 2u == 0u ? even : odd) * (0.5f + 0.5f * std::abs(a_dir.z)); }
};

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
  // a_offsets[y]: how many pixels above row y hit something (an exclusive scan of the rows' hits).
  virtual void RowOffsets(const float* a_depth [[size("m_width * m_height")]], uint32_t* a_offsets [[size("m_height")]]);
  virtual void CommitDeviceData() {}

  std::vector<std::shared_ptr<IShade>> m_shades;  // per instance

  uint32_t m_hitCount = 0;  // pixels that hit something, in the last Render
  float m_meanDepth = 0.0f; // their mean depth
  float m_maxDepth = 0.0f;

protected:
  void kernel2D_Render(uint32_t* a_color, float* a_depth, int a_width, int a_height);
  void kernel1D_CollectHits(const float* a_depth, int a_count);
  void kernel1D_CopySorted(float* a_sorted, uint32_t* a_count);
  void kernel1D_CountRows(const float* a_depth, int a_width, int a_height);
  void kernel1D_CopyOffsets(uint32_t* a_offsets, int a_height);

  float3 EyeRayDir(int x, int y) const;

  std::shared_ptr<ISceneObject> m_pAccelStruct;
  std::vector<float> m_hitDepths;
  std::vector<uint32_t> m_rowHits, m_rowOffsets;
  float4 m_eye = float4(0.0f, 0.0f, 3.0f, 0.0f);
  float m_tanHalfFov = 0.5f;
  int m_width, m_height;
};
