// ISceneObject over signed distance fields in the paper's level-3 form (section 3.10, listing 2):
// RayQuery_NearestHit walks its own tree over the leaf boxes of every placed field and, at a leaf,
// calls m_geom[info.geomId]->Intersect(posAndNear, dirAndFar, info, hit, this), a virtual call with
// a CRT_LeafInfo. Each representation is a class of its own, whose Intersect reads the field's values
// from the scene through `this`:
//   - SdfGridLeaves: a dense grid; a leaf is a brick of brickCells^3 of its cells, where the
//     surface may cross it (its samples are not all of one sign);
//   - SdfSVSLeaves:  a sparse voxel set; a leaf is a voxel and its 8 corner values;
//   - SdfSBSLeaves:  a sparse brick set; a leaf is a brick and its (b+1)^3 values.
// A class composing it (crossrt_add_class(... COMPOSE ISceneObject=SdfLeafScene)) runs the walk on the
// GPU with a switch over the field's class, and at VIRTUAL_LEVEL 3, where the device has ray tracing
// pipelines, lets the hardware walk the leaf boxes (LeafBoxes) with an intersection shader per
// representation. BVHScene traces the same fields faster in software (its bricks are leaves of its
// own tree, not virtual calls); this class is the form the hardware can take over.
//
// Fields are added as BVHScene takes them (AddGeom_SdfGrid/SVS/SBS, values dequantised to floats) and
// placed with AddInstance; triangle meshes and box geometry are BVHScene's. A hit reports t, the leaf
// (a brick of a grid, a voxel of an SVS, a brick of an SBS) as primId, the instance and the field,
// and the object-space normal in coords[0..2].
#pragma once
#include "CrossRT.h"
#include "SdfStructures.h"
#include "Specialize.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

class SdfLeafScene;

// A placed field (the paper's AbstractObject): its leaves' intersection, and where it is.
struct ISdfLeaves
{
  virtual ~ISdfLeaves() = default;
  // Updates hit when the ray (pos + t * dir, t in [near, hit.t), world space) meets the field inside
  // leaf info.aabbId nearer.
  virtual void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit,
                         const SdfLeafScene* scene) const = 0;
};

// Rows 0-2 of an instance's world-to-object matrix (the ray is moved into the field's space, where t
// is the same), and the ids a hit reports.
struct SdfPlacement
{
  LiteMath::float4 toObject0, toObject1, toObject2;
  uint32_t geomId = 0, instId = 0;
};

class SdfGridLeaves : public ISdfLeaves
{
public:
  void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit,
                 const SdfLeafScene* scene) const override;
  SdfPlacement place;
  LiteMath::float4 boxMinAndCell;  // the grid's corner, and its cells' edge
  uint32_t firstValue = 0, samples = 0, brickCells = 0, bricksPerAxis = 0;
  uint32_t firstBrick = 0;  // leaf i is brick m_gridBricks[firstBrick + i]: x + n (y + n z), n = bricksPerAxis
};

class SdfSVSLeaves : public ISdfLeaves
{
public:
  void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit,
                 const SdfLeafScene* scene) const override;
  SdfPlacement place;
  uint32_t firstVoxel = 0, voxelCount = 0;  // in the scene's m_voxels
};

class SdfSBSLeaves : public ISdfLeaves
{
public:
  void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit,
                 const SdfLeafScene* scene) const override;
  SdfPlacement place;
  uint32_t firstBrick = 0, brickCount = 0, brickSize = 0;  // in the scene's m_bricks
};

class SdfLeafScene : public ISceneObject
{
public:
  // brickCells: a grid's leaves are bricks of brickCells^3 cells (its cells per axis a multiple of it).
  explicit SdfLeafScene(uint32_t gridBrickCells = 4) : m_gridBrickCells(gridBrickCells) {}

  const char* Name() const override { return "SdfLeafScene"; }
  void ClearGeom() override;
  // Triangle meshes are BVHScene's: these throw std::runtime_error.
  uint32_t AddGeom_Triangles3f(const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum, uint32_t flags = BUILD_HIGH,
                               size_t vByteStride = 3 * sizeof(float)) override;
  void UpdateGeom_Triangles3f(uint32_t geomId, const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum,
                              uint32_t flags = BUILD_HIGH, size_t vByteStride = 3 * sizeof(float)) override;
  uint32_t AddGeom_SdfGrid(const litesdf::SdfGrid& grid, uint32_t flags = BUILD_HIGH) override;
  uint32_t AddGeom_SdfSVS(const litesdf::SdfSVS& svs, uint32_t flags = BUILD_HIGH) override;
  uint32_t AddGeom_SdfSBS(const litesdf::SdfSBS& sbs, uint32_t flags = BUILD_HIGH) override;
  void ClearScene() override;
  uint32_t AddInstance(uint32_t geomId, const LiteMath::float4x4& matrix) override;
  void UpdateInstance(uint32_t instanceId, const LiteMath::float4x4& matrix) override;
  void CommitScene(uint32_t options = BUILD_HIGH) override;
  CRT_Hit RayQuery_NearestHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) override;
  bool RayQuery_AnyHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) override;

  // The world-space boxes of m_geom[geomId]'s leaves, in the order of CRT_LeafInfo::aabbId: what the
  // ray tracing hardware walks at VIRTUAL_LEVEL 3.
  std::vector<CRT_AABB> LeafBoxes(uint32_t geomId) const;

  // The first hit of the ray (field space) with the cells of a brick of n^3 cells of edge `cell` from
  // `corner`, whose corner values are m_values[first + x + y * strideY + z * strideZ], within [t0, t1].
  // MarchBrick solves the brick m_intersectRepeats times (see below) and returns the first answer.
  litesdf::SdfHit MarchBrick(LiteMath::float3 corner, float cell, int n, uint32_t first, uint32_t strideY, uint32_t strideZ,
                             LiteMath::float3 org, LiteMath::float3 dir, float t0, float t1) const;
  litesdf::SdfHit MarchBrickOnce(LiteMath::float3 corner, float cell, int n, uint32_t first, uint32_t strideY, uint32_t strideZ,
                                 LiteMath::float3 org, LiteMath::float3 dir, float t0, float t1) const;

  // ---- Profiling: how a frame's time splits into the walk and the bricks' intersection. ----
  // With m_intersectRepeats = k, every grid or SBS brick a ray reaches is solved k times; the hits do
  // not change. A frame then takes walk + k * intersection, so two frames (k = 1 and k = 3) give both
  // parts, on every backend and in intersection shaders alike (bench_sdf, the paper's Figure 10). The
  // repeats end their span at t1 + m_repeatSlack, 0, which no compiler can prove equal to t1, so none
  // merges them. A specialization constant on the GPU: the usual k = 1 compiles to one solve.
  CRT_SPECIALIZE uint32_t m_intersectRepeats = 1;
  float m_repeatSlack = 0.0f;

  // ---- Device data, rebuilt by CommitScene: what the traversal and the leaves read. ----
  std::vector<std::shared_ptr<ISdfLeaves>> m_geom;  // per instance, in instance order
  std::vector<float> m_values;                      // grids' samples and SBS bricks' values
  std::vector<uint32_t> m_gridBricks;               // grids' bricks that the surface may cross (their leaves)
  std::vector<float> m_voxelValues;                 // SVS voxels: 8 corner values each
  std::vector<LiteMath::float4> m_voxels;           // SVS voxels: corner, edge
  std::vector<LiteMath::float4> m_bricks;           // SBS bricks: corner, voxel edge
  std::vector<uint32_t> m_brickValues;              // SBS bricks: their first value in m_values
  // The tree, depth first: node i has the box [m_nodeMin[i], m_nodeMax[i]] (xyz). An inner node's
  // children are i + 1 and m_nodeRight[i]; a leaf node has m_nodeLeaf[i] = 1 + its leaf's index in
  // m_leafIds, (element of m_geom, aabbId); an inner node has 0 there.
  std::vector<LiteMath::float4> m_nodeMin, m_nodeMax;
  std::vector<uint32_t> m_nodeRight, m_nodeLeaf;
  std::vector<LiteMath::uint2> m_leafIds;

private:
  struct Field
  {
    int kind = 0;  // 0 grid, 1 SVS, 2 SBS
    std::shared_ptr<ISdfLeaves> prototype;  // its data, without a placement
    std::vector<CRT_AABB> leafBoxes;        // field space
  };
  struct Leaf
  {
    CRT_AABB box;
    uint32_t element, aabbId;
  };
  uint32_t Build(std::vector<Leaf>& leaves, size_t begin, size_t end);

  uint32_t m_gridBrickCells;
  std::vector<Field> m_fields;
  std::vector<std::pair<uint32_t, LiteMath::float4x4>> m_instances;  // (geomId, object-to-world)
};
