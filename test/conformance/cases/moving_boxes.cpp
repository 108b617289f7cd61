#include "moving_boxes.h"

MovingBoxes::MovingBoxes()
{
  m_pAccelStruct = std::shared_ptr<ISceneObject>(CreateSceneRT("sah"), DeleteSceneRT);

  // Eight boxes in a row along x at z in [1, 2], two per custom primitive.
  CRT_AABB boxes[8];
  for (int i = 0; i < 8; i++)
  {
    boxes[i].boxMin = float4(float(i), 0.0f, 1.0f, 0.0f);
    boxes[i].boxMax = float4(float(i) + 0.9f, 1.0f, 2.0f, 0.0f);
  }
  const uint32_t boxGeom = m_pAccelStruct->AddGeom_AABB(1, boxes, 8, nullptr, 4);

  // A quad in the z = 0 plane that slides 8 along x, then drops by 1.
  const float verts[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const uint32_t indices[] = {0, 1, 2, 0, 2, 3};
  const uint32_t quad = m_pAccelStruct->AddGeom_Triangles3f(verts, 4, indices, 6);
  const float4x4 steps[3] = {float4x4(), translate4x4(float3(8, 0, 0)), translate4x4(float3(8, 0, -1))};

  m_pAccelStruct->ClearScene();
  m_pAccelStruct->AddInstance(boxGeom, translate4x4(float3(0, 0, 2)));
  m_pAccelStruct->AddInstanceMotion(quad, steps, 3);
  m_pAccelStruct->CommitScene(BUILD_HIGH | MOTION_BLUR);
}

void MovingBoxes::Trace(uint32_t n, const float4* a_org, const float4* a_dir, int* a_what, float* a_dist, float a_time)
{
  kernel1D_Trace(n, a_org, a_dir, a_what, a_dist, a_time);
}

void MovingBoxes::kernel1D_Trace(uint32_t n, const float4* a_org, const float4* a_dir, int* a_what, float* a_dist, float a_time)
{
  for (uint32_t i = 0; i < n; i++)
  {
    const CRT_Hit hit = m_pAccelStruct->RayQuery_NearestHitMotion(a_org[i], a_dir[i], a_time);
    if (hit.primId == 0xFFFFFFFFu)
      a_what[i] = -1;
    else if ((hit.geomId & CRT_GEOM_MASK_AABB_BIT) != 0)
      a_what[i] = 1000 + int(hit.primId);
    else
      a_what[i] = int(hit.primId);
    a_dist[i] = hit.t;
  }
}
