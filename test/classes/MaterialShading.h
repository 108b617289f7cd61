// Virtual functions in kernels: a std::vector of materials behind an interface, with three
// implementations whose data differ in size (12, 28 and 36 bytes), a method two of them inherit,
// and implementations that call their own helpers and a free function
// (test/equivalence/test_virtual.cpp).
#pragma once
#include "LiteMath.h"

#include <cstdint>
#include <memory>
#include <vector>

using LiteMath::float3;
using LiteMath::float4;

struct IMaterial
{
  virtual ~IMaterial() = default;
  // Reflected colour for a unit normal and a unit direction to the light.
  virtual float3 Shade(float3 normal, float3 toLight) const = 0;
  virtual float Opacity() const { return 1.0f; }
  // Dims `color` with the distance it travelled (CallableShading calls it: a result through a reference).
  virtual void Attenuate(float3& color, float distance) const { color = color / (1.0f + distance * distance); }
};

inline float Lit(float3 normal, float3 toLight) { return LiteMath::max(LiteMath::dot(normal, toLight), 0.0f); }

struct Lambert : IMaterial
{
  float3 albedo{0.5f, 0.5f, 0.5f};
  float3 Shade(float3 normal, float3 toLight) const override { return albedo * Lit(normal, toLight); }
};

struct Phong : IMaterial
{
  float3 diffuse{0.4f, 0.2f, 0.1f};
  float3 specular{0.5f, 0.5f, 0.5f};
  float shininess = 16.0f;
  float3 Shade(float3 normal, float3 toLight) const override
  {
    return diffuse * Lit(normal, toLight) + specular * Highlight(normal, toLight);
  }
  float Highlight(float3 normal, float3 toLight) const
  {
    const float3 reflected = 2.0f * LiteMath::dot(normal, toLight) * normal - toLight;
    return std::pow(LiteMath::max(reflected.z, 0.0f), shininess);  // the viewer looks down -z
  }
};

struct Checker : IMaterial
{
  float3 even{1.0f, 1.0f, 1.0f};
  float3 odd{0.1f, 0.1f, 0.1f};
  float scale = 4.0f;
  int axis = 0;
  float opacity = 0.5f;
  float3 Shade(float3 normal, float3 toLight) const override
  {
    const float coordinate = axis == 0 ? normal.x : axis == 1 ? normal.y : normal.z;
    const int cell = int(std::floor(coordinate * scale));
    return ((cell & 1) == 0 ? even : odd) * Lit(normal, toLight);
  }
  float Opacity() const override { return opacity; }
  void Attenuate(float3& color, float distance) const override { color = color * LiteMath::max(1.0f - distance * opacity, 0.0f); }
};

class MaterialShading
{
public:
  MaterialShading() = default;
  virtual ~MaterialShading() = default;

  // colors[i] = (material materialIds[i] lit from m_toLight at normals[i], its opacity).
  virtual void Shade(int n, [[crossrt::size("n")]] const float4* normals, [[crossrt::size("n")]] const uint32_t* materialIds,
                     [[crossrt::size("n")]] float4* colors);
  virtual void CommitDeviceData() {}

  std::vector<std::shared_ptr<IMaterial>> m_materials;
  float3 m_toLight{0.0f, 0.0f, 1.0f};

protected:
  void kernel1D_Shade(int n, const float4* normals, const uint32_t* materialIds, float4* colors);
};
