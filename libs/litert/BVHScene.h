// ISceneObject over CrossRT's own BVHs: one tree per mesh (of triangles, or of boxes for custom
// primitives), a top-level tree over the instances (moving ones bounded over their motion),
// both built by a pluggable builder (the LBVH as written, LBVH_CPU, LBVH_Vulkan, binned SAH), and a
// stack-based traversal with watertight ray/triangle tests and robust slab tests.
//
// The traversal is written in the translator's conventions, so a class that holds an ISceneObject
// can run it on the GPU by composition: crossrt_add_class(... COMPOSE ISceneObject=BVHScene)
// prints RayQuery_NearestHit/AnyHit and what they call into its shaders, and uploads the "device
// data" members below with the class's own.
#pragma once
#include "BVHNode.h"
#include "CrossRT.h"
#include "Specialize.h"

#include <functional>
#include <string>
#include <vector>

// The traversal's node: four children side by side, their boxes one lane each (so one step tests
// four boxes with float4 arithmetic, and a tree has half the levels of a binary one). 128 bytes,
// std430 as in C++. CommitScene collapses every builder's binary tree into these.
struct BVH4Node
{
  LiteMath::float4 minX, maxX, minY, maxY, minZ, maxZ;  // an empty lane is the empty box (+inf, -inf)
  LiteMath::uint4 child;  // an inner child's node index, or BVH4Leaf(first, count), or kNoChild
  LiteMath::uint4 unused;
};

// A leaf lane of a mesh tree holds up to 8 primitives, in groups of four (BVHTriangle4):
// kLeafFlag | first group << 3 | (groups - 1). A leaf of the top tree holds up to 8 instances:
// kLeafFlag | first << 3 | (count - 1).
constexpr uint32_t kMaxLeafSize = 8;
constexpr uint32_t kNoChild = 0xFFFFFFFFu;  // an empty lane (its box is never entered)

// A triangle's corners.
struct BVHTriangle
{
  LiteMath::float3 v0, v1, v2;
};

// Four triangles side by side, one lane each, so that one test covers four with float4
// arithmetic: coord[3 * corner + axis] holds that coordinate of the four. A lane without a
// triangle holds NaN, which no ray hits. 144 bytes, std430 as in C++.
struct BVHTriangle4
{
  LiteMath::float4 coord[9];
};

// An instance as the traversal reads it: rows 0-2 of its world-to-object matrix, the ids a hit
// reports, the root of its mesh's tree in BVHScene::m_nodes, what kind of instance it is, and for a
// moving one where its object-to-world rows are. 80 bytes, std430 as in C++.
constexpr uint32_t kInstanceIdentity = 1u;  // toObject is the identity: the world ray is the object ray
constexpr uint32_t kInstanceBoxes = 2u;     // its geometry is boxes (AddGeom_AABB): leaves index m_boxes
constexpr uint32_t kInstanceMotion = 4u;    // it moves: toObject comes from m_motion at the ray's time
constexpr uint32_t kInstanceSdf = 8u;       // its geometry is a signed distance field: leaves' boxes are m_sdfBricks
// What a scene holds, for the traversal to leave out the rest (BVHScene::m_sceneKinds): the instance
// flags above that some instance has (kInstanceBoxes also for fields, whose bricks are boxes), and:
constexpr uint32_t kSceneTriangles = 16u;    // an instance of a triangle mesh
constexpr uint32_t kSceneTransformed = 32u;  // a still instance whose matrix is not the identity
struct BVHInstance
{
  LiteMath::float4 toObjectRow0, toObjectRow1, toObjectRow2;
  uint32_t instId, geomId, root;
  uint32_t flags;                     // kInstance*
  uint32_t motionFirst, motionSteps;  // a moving instance: its object-to-world rows 0-2 per step, at m_motion[motionFirst...]
  uint32_t unused0, unused1;
};

// A brick of a signed distance field: voxels^3 voxels of edge minAndVoxelSize.w from
// minAndVoxelSize.xyz, whose (voxels + 1)^3 corner values are read from m_sdfWords: the one at
// corner (x, y, z) is value number firstValue + (z * stride + y) * stride + x, packed bytesPerValue
// bytes at a time (1 and 2: quantised over +-the voxel's diagonal; 4: the float). A voxel of an SVS
// is a brick of one voxel, a brick of an SBS one of its bricks, a dense grid bricks of 8^3 cells
// (stride: the grid's samples per axis). localId is what a hit reports as primId (0 for a grid's).
// A brick of at most 4^3 voxels has a bit per voxel, x + n (y + n z), set where a corner value is
// <= 0 (litesdf's MayHoldSurface), in occupied[0] (bits 0-31) and occupied[1]: the traversal skips
// the others without reading their corners. 48 bytes, std430 as in C++.
struct BVHSdfBrick
{
  LiteMath::float4 minAndVoxelSize;
  uint32_t firstValue, voxels, stride, bytesPerValue;
  uint32_t localId;
  uint32_t occupied[2];
  uint32_t unused;
};
constexpr uint32_t kSdfMaskedVoxels = 4;  // bricks of up to 4^3 voxels have occupancy bits
constexpr int kSdfNewtonIterations = 4;  // per voxel the ray crosses

// A ray prepared for one tree: slab test reciprocals (0 for a zero or denormal direction
// component) and the watertight test's shear (Woop, Benthin and Wald 2013).
struct BVHTraceRay
{
  LiteMath::float3 org, dir, invDir;
  float tnear;
  int kx, ky, kz;
  float sx, sy, sz;
  bool anyZeroAxis;
};

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
  // Box geometry and moving instances (CrossRT.h).
  using ISceneObject::AddGeom_AABB;  // and the forms without build flags
  using ISceneObject::UpdateGeom_AABB;
  uint32_t AddGeom_AABB(uint32_t typeId, const CRT_AABB* boxMinMaxF8, size_t boxNumber, uint32_t buildFlags, void** customPrimPtrs,
                        size_t customPrimCount) override;
  void UpdateGeom_AABB(uint32_t geomId, uint32_t typeId, const CRT_AABB* boxMinMaxF8, size_t boxNumber, uint32_t buildFlags,
                       void** customPrimPtrs, size_t customPrimCount) override;
  uint32_t AddInstanceMotion(uint32_t geomId, const LiteMath::float4x4* matrices, uint32_t matrixNumber) override;
  // Signed distance fields (CrossRT.h): boxes of bricks (BVHSdfBrick) under a tree of their own.
  uint32_t AddGeom_SdfGrid(const litesdf::SdfGrid& grid, uint32_t flags = BUILD_HIGH) override;
  uint32_t AddGeom_SdfSVS(const litesdf::SdfSVS& svs, uint32_t flags = BUILD_HIGH) override;
  uint32_t AddGeom_SdfSBS(const litesdf::SdfSBS& sbs, uint32_t flags = BUILD_HIGH) override;
  CRT_Hit RayQuery_NearestHitMotion(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, float time) override;
  bool RayQuery_AnyHitMotion(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, float time = 0.0f) override;
  // Triangle meshes placed still; a scene with boxes or moving instances is not exported (false).
  bool ExportScene(CRT_SceneExport& out) const override;

  // The tree of mesh geomId (for SAH cost and statistics).
  const BVHTree& MeshTree(uint32_t geomId) const { return m_meshes.at(geomId).tree; }

  // ---- Device data: what the traversal reads, rebuilt by CommitScene and empty until then. ----
  // Public because a class composing BVHScene uploads them to the GPU.
  std::vector<BVH4Node> m_nodes;         // the top tree (root 0, leaves index m_instances), then every mesh's
  std::vector<BVHInstance> m_instances;  // in the top tree's leaf order
  std::vector<BVHTriangle4> m_triangles;  // every mesh's triangles in leaf order, four per group (leaves index here)
  std::vector<uint32_t> m_primIds;        // lane l of m_triangles[g] is triangle m_primIds[4 * g + l] of its mesh
  std::vector<BVH4Node> m_boxes;          // box geometry's boxes in leaf order, four per group, a lane's child its primitive
  std::vector<LiteMath::float4> m_motion; // moving instances' object-to-world rows 0-2, per time step
  std::vector<BVHSdfBrick> m_sdfBricks;   // every signed distance field's bricks (an SDF's box lanes index here)
  std::vector<uint32_t> m_sdfWords;       // their corner values, packed
  // The kinds of geometry and instances the committed scene holds (kScene*). A _Vulkan class composing
  // BVHScene compiles its traversal for these (CRT_SPECIALIZE): a scene of still triangle meshes gets
  // no code for boxes, fields or motion. Everywhere else it only skips tests that would fail anyway.
  CRT_SPECIALIZE uint32_t m_sceneKinds = 0;

private:
  struct Mesh
  {
    bool boxes = false;                  // box geometry (AddGeom_AABB, or an SDF's): boxGroups instead of triangles
    bool sdf = false;                    // a signed distance field: boxGroups' lanes index sdfBricks
    std::vector<BVHSdfBrick> sdfBricks;  // its bricks, with values in sdfWords
    std::vector<uint32_t> sdfWords;
    std::vector<BVH4Node> boxGroups;     // what wide's leaves index: each leaf's boxes, four per group
    BVHTree tree;                        // as the builder made it
    std::vector<BVH4Node> wide;          // the same tree collapsed for the traversal (empty without triangles)
    std::vector<BVHTriangle> triangles;  // triangles[k] is triangle tree.primIndices[k]
    std::vector<BVHTriangle4> groups;    // what wide's leaves index: each leaf's triangles, four per group
    std::vector<uint32_t> groupPrims;    // lane l of groups[g] is triangle groupPrims[4 * g + l] (or none)
  };
  struct Instance
  {
    uint32_t geomId;
    LiteMath::float4x4 toWorld, toObject;
    std::vector<LiteMath::float4x4> motion;  // a moving instance: toWorld at evenly spaced times over [0, 1]
  };
  void SetMesh(Mesh& mesh, const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum, size_t vByteStride);
  void SetBoxes(Mesh& mesh, const CRT_AABB* boxes, size_t boxNumber, size_t customPrimCount);
  uint32_t AddSdf(std::vector<BVHSdfBrick> bricks, std::vector<uint32_t> words);
  void ClearDeviceData();

  // The traversal (translated for the GPU when composed).
  CRT_Hit NearestHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, float time) const;
  bool AnyHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, float time) const;
  bool Trace(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, float time, bool anyHit, CRT_Hit& hit) const;
  bool TraceTogether(const BVHTraceRay& ray, float time, bool anyHit, float& tfar, CRT_Hit& hit) const;
  bool TraceInstance(uint32_t k, const BVHTraceRay& worldRay, float time, bool anyHit, float& tfar, CRT_Hit& hit) const;
  bool TraceMesh(const BVHTraceRay& ray, uint32_t root, uint32_t leaves, bool anyHit, float& tfar, CRT_Hit& hit) const;
  bool TraceMeshTogether(const BVHTraceRay& ray, uint32_t root, bool anyHit, float& tfar, CRT_Hit& hit) const;
  bool TraceMeshQuads(const BVHTraceRay& gangRay, uint32_t rays, uint32_t root, bool anyHit, float& tfar, CRT_Hit& hit) const;
  bool TakeNearestHit(uint32_t g, uint32_t hits, const LiteMath::float4& t, const LiteMath::float4& u, const LiteMath::float4& v,
                      bool anyHit, float& tfar, CRT_Hit& hit) const;
  uint32_t IntersectGroup(const BVHTraceRay& r, uint32_t group, int kx, int ky, int kz, float tfar, LiteMath::float4& t, LiteMath::float4& u,
                          LiteMath::float4& v) const;
  bool IntersectTriangle(const BVHTraceRay& r, uint32_t group, int lane, int kx, int ky, int kz, float tfar, float& t, float& u, float& v,
                         bool& onEdge) const;
  bool IntersectCorners(const BVHTraceRay& r, int kx, int ky, int kz, LiteMath::float3 a, LiteMath::float3 b, LiteMath::float3 c, float tfar,
                        float& t, float& u, float& v, bool& onEdge) const;
  bool IntersectBoxes(const BVHTraceRay& r, uint32_t group, bool sdf, float& tfar, CRT_Hit& hit) const;
  bool IntersectSdfBrick(const BVHTraceRay& r, uint32_t brick, float tEnter, float tExit, float& tfar, CRT_Hit& hit) const;
  uint32_t SdfCode(uint32_t at, uint32_t bytes) const;

  std::string m_name;
  Builder m_builder;
  std::vector<Mesh> m_meshes;
  std::vector<Instance> m_placed;  // instances as added (m_instances holds them in top-tree order)
};
