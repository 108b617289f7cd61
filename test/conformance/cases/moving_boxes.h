// A scene of custom-primitive boxes and a moving quad, built the paper's way (CreateSceneRT,
// AddGeom_AABB, AddInstanceMotion, CommitScene with MOTION_BLUR) and traced at a time per call.
#pragma once
#include "CrossRT.h"
#include "LiteMath.h"
#include <cstdint>
#include <memory>
using namespace LiteMath;

class MovingBoxes
{
public:
  MovingBoxes();
  virtual ~MovingBoxes() = default;

  // What ray i (origin xyz + tmin, direction xyz + tmax) reaches at time a_time: the box
  // primitive's id + 1000, the quad's triangle id, or -1; and the distance.
  virtual void Trace(uint32_t n, const float4* a_org [[size("n")]], const float4* a_dir [[size("n")]], int* a_what [[size("n")]],
                     float* a_dist [[size("n")]], float a_time);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Trace(uint32_t n, const float4* a_org, const float4* a_dir, int* a_what, float* a_dist, float a_time);

  std::shared_ptr<ISceneObject> m_pAccelStruct;
};
