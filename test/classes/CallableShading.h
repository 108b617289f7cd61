// MaterialShading's materials over an image (a 2D kernel), translated with VIRTUAL_LEVEL 3: where the
// device has ray tracing pipelines the kernel runs as a ray generation shader and each class's
// methods as callable shaders; elsewhere (lavapipe) it switches over the class as at level 2.
// Attenuate returns its result through a reference, which the callable's payload carries back
// (test/equivalence/test_virtual.cpp).
#pragma once
#include "MaterialShading.h"

class CallableShading
{
public:
  virtual ~CallableShading() = default;

  // colors[y * width + x] = (the material shaded and dimmed over a distance growing with x + y, its opacity).
  virtual void Render(int width, int height, [[crossrt::size("width * height")]] const float4* normals,
                      [[crossrt::size("width * height")]] const uint32_t* materialIds, [[crossrt::size("width * height")]] float4* colors);
  virtual void CommitDeviceData() {}

  std::vector<std::shared_ptr<IMaterial>> m_materials;
  float3 m_toLight{0.0f, 0.0f, 1.0f};
  float m_distanceStep = 0.01f;

protected:
  void kernel2D_Render(int width, int height, const float4* normals, const uint32_t* materialIds, float4* colors);
};
