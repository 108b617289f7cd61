// Virtual calls through a std::vector of pointers to an interface, one implementation per material:
// on an element (m_materials[k]->Shade) and through a local pointer to one (material->Shade). Its
// members m_materials_tags, m_materials_objects and m_materials_Lambert have the names the generated
// code once gave the vector's per-element tags, per-class arrays and dispatchers (issue 52).
#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <memory>
#include <vector>
using namespace LiteMath;

struct IMaterial
{
  virtual ~IMaterial() = default;
  virtual float3 Shade(float3 n, float3 l) const = 0;
};

struct Lambert : public IMaterial
{
  float3 albedo;
  float3 Shade(float3 n, float3 l) const override { return albedo * std::max(dot(n, l), 0.0f); }
};

struct Mirror : public IMaterial
{
  float3 tint;
  float power = 8.0f;
  float3 Shade(float3 n, float3 l) const override { return tint * std::pow(std::max(n.z * l.z, 0.0f), power); }
};

class ShadedSpheres
{
public:
  ShadedSpheres();
  virtual void Shade(uint32_t n, const float4* a_normals [[size("n")]], float4* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}
  std::vector<std::shared_ptr<IMaterial>> m_materials;

protected:
  void kernel1D_Shade(uint32_t n, const float4* a_normals, float4* a_out);
  float3 m_light;
  float m_materials_tags = 0.5f;
  float m_materials_objects = 0.25f;
  float m_materials_Lambert = 0.125f;
  float m_materials_Mirror = 0.0625f;
  float m_materials_Shade = 0.03125f;  // and its dispatcher of Shade
};
