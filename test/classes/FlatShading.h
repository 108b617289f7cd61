// MaterialShading's kernel in a class of its own, translated with VIRTUAL_LEVEL 1: on the GPU every
// material sits in one array of equal slots (test/equivalence/test_virtual.cpp runs both levels).
#pragma once
#include "MaterialShading.h"

class FlatShading
{
public:
  virtual ~FlatShading() = default;

  // As MaterialShading::Shade.
  virtual void Shade(int n, [[crossrt::size("n")]] const float4* normals, [[crossrt::size("n")]] const uint32_t* materialIds,
                     [[crossrt::size("n")]] float4* colors);
  virtual void CommitDeviceData() {}

  std::vector<std::shared_ptr<IMaterial>> m_materials;
  float3 m_toLight{0.0f, 0.0f, 1.0f};

protected:
  void kernel1D_Shade(int n, const float4* normals, const uint32_t* materialIds, float4* colors);
};
