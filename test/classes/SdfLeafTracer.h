// The paper's level-3 form over signed distance fields, as a user composes it: SdfLeafTracer traces
// rays through an ISceneObject, which the generated classes run as litert's SdfLeafScene
// (COMPOSE ISceneObject=SdfLeafScene). Its traversal calls m_geom[info.geomId]->Intersect(ray, info,
// hit, this) at each leaf, with a class per representation (grid, SVS, SBS): on the GPU a switch over
// the field's class, or at VIRTUAL_LEVEL 3 an intersection shader per class with the hardware walking
// the leaves' boxes (test/equivalence/test_sdf_leaves.cpp).
#pragma once
#include "CrossRT.h"
#include "LiteMath.h"

#include <cstdint>
#include <memory>

class SdfLeafTracer
{
public:
  SdfLeafTracer() = default;
  virtual ~SdfLeafTracer() = default;
  void SetScene(std::shared_ptr<ISceneObject> scene) { m_scene = std::move(scene); }
  // hits[i]: the nearest field along the ray from origins[i] (xyz; w: near) in direction dirs[i] (xyz; w: far).
  virtual void Trace(int n, [[crossrt::size("n")]] const LiteMath::float4* origins, [[crossrt::size("n")]] const LiteMath::float4* dirs,
                     [[crossrt::size("n")]] CRT_Hit* hits);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Trace(int n, const LiteMath::float4* origins, const LiteMath::float4* dirs, CRT_Hit* hits);
  std::shared_ptr<ISceneObject> m_scene;
};
