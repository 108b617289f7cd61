// Ray queries and arrays of textures in one kernel: each ray's nearest hit, shaded with the
// texture of the mesh it hit at its barycentrics. PrimaryRays-style composition of ISceneObject
// (COMPOSE ISceneObject=BVHScene), so the kernel gets all four shaders: with and without ray tracing
// hardware, each with the GPU's samplers and with textures sampled from buffers
// (test/equivalence/test_texture_arrays.cpp).
#pragma once
#include "CrossRT.h"
#include "Image2D.h"
#include "LiteMath.h"

#include <cstdint>
#include <memory>
#include <vector>

class TexturedHits
{
public:
  TexturedHits() = default;
  virtual ~TexturedHits() = default;

  void SetScene(std::shared_ptr<ISceneObject> a_scene) { m_pAccelStruct = std::move(a_scene); }
  // colors[i]: the texture of the mesh ray i hits first, sampled at the hit's barycentrics; black on a miss.
  virtual void Shade(int n, [[crossrt::size("n")]] const LiteMath::float4* posAndNear, [[crossrt::size("n")]] const LiteMath::float4* dirAndFar,
                     [[crossrt::size("n")]] LiteMath::float4* colors);
  virtual void CommitDeviceData() {}

  std::vector<LiteImage::Texture2D<LiteMath::float4>> m_meshTextures;  // one per mesh (geomId)

protected:
  void kernel1D_Shade(int n, const LiteMath::float4* posAndNear, const LiteMath::float4* dirAndFar, LiteMath::float4* colors);

  std::shared_ptr<ISceneObject> m_pAccelStruct;
};
