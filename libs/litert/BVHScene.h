// ISceneObject over CrossRT's own BVHs: one tree per mesh, a top-level tree over the instances,
// both built by a pluggable builder (the LBVH as written, LBVH_CPU, LBVH_Vulkan, binned SAH), and a
// stack-based traversal with watertight ray/triangle tests and robust slab tests.
#pragma once
#include "BVHNode.h"
#include "CrossRT.h"

#include <functional>
#include <string>
#include <vector>

class BVHScene : public ISceneObject
{
public:
  // Builds a tree over boxes[0, count), count > 0.
  using Builder = std::function<BVHTree(const LiteMath::Box4f* boxes, int count)>;
  BVHScene(std::string name, Builder builder);

  const char* Name() const override { return m_name.c_str(); }
  void ClearGeom() override;
  uint32_t AddGeom_Triangles3f(const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum,
                               uint32_t flags = BUILD_HIGH, size_t vByteStride = 3 * sizeof(float)) override;
  void UpdateGeom_Triangles3f(uint32_t geomId, const float* vpos3f, size_t vertNum, const uint32_t* triIndices,
                              size_t indNum, uint32_t flags = BUILD_HIGH, size_t vByteStride = 3 * sizeof(float)) override;
  void ClearScene() override;
  uint32_t AddInstance(uint32_t geomId, const LiteMath::float4x4& matrix) override;
  void UpdateInstance(uint32_t instanceId, const LiteMath::float4x4& matrix) override;
  void CommitScene(uint32_t options = BUILD_HIGH) override;
  CRT_Hit RayQuery_NearestHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) override;
  bool RayQuery_AnyHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) override;

  // The tree of mesh geomId (for SAH cost and statistics).
  const BVHTree& MeshTree(uint32_t geomId) const { return m_meshes.at(geomId).tree; }

  // A triangle's corners, stored in the order of the tree's leaves.
  struct Triangle
  {
    LiteMath::float3 v0, v1, v2;
  };

private:
  struct Mesh
  {
    BVHTree tree;
    std::vector<Triangle> triangles;  // triangles[k] is triangle tree.primIndices[k]
  };
  struct Instance
  {
    uint32_t geomId;
    LiteMath::float4x4 toWorld, toObject;
  };
  template <bool anyHit>
  bool Trace(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, CRT_Hit& hit) const;
  void SetMesh(Mesh& mesh, const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum, size_t vByteStride);

  std::string m_name;
  Builder m_builder;
  std::vector<Mesh> m_meshes;
  std::vector<Instance> m_instances;
  BVHTree m_top;  // over the instances with triangles; primIndices are instance ids
  bool m_committed = false;
};
