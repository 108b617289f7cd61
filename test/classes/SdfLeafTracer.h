// The paper's listing 2 (section 3.10) over signed distance fields, written as a user writes it:
// SdfLeafScene's traversal walks its own tree over every field's leaf boxes and, at each leaf,
// calls m_geom[info.geomId]->Intersect(posAndNear, dirAndFar, info, hit, this), where info is a
// CRT_LeafInfo and `this` gives the field's code the scene's data. One class per representation:
//   - SdfGridGeom, a dense grid of samples: a leaf is a brick of cells of it;
//   - SdfSVSGeom, a sparse voxel set: a leaf is a voxel with its 8 corner values;
//   - SdfSBSGeom, a sparse brick set: a leaf is a brick with its (b+1)^3 values.
// On the GPU the call is a switch over the field's class, or at VIRTUAL_LEVEL 3 an intersection
// shader per class with the hardware walking the leaves' boxes (test/equivalence/test_sdf_leaves.cpp).
#pragma once
#include "CrossRT.h"
#include "LiteMath.h"
#include "SdfStructures.h"

#include <cstdint>
#include <memory>
#include <vector>

class SdfLeafScene;

// A field in the scene: what its leaves are made of.
struct ISdfGeom
{
  virtual ~ISdfGeom() = default;
  // Updates hit when the ray (pos + t * dir, t in [near, hit.t)) meets the field inside leaf
  // info.aabbId nearer: t, primId (the leaf), geomId and the normal (coords[0..2]).
  virtual void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit,
                         const SdfLeafScene* scene) const = 0;
};

// A dense grid of samples x samples x samples values from m_values[firstValue], x fastest: its
// leaves are bricks of brickCells^3 cells, brick b at (b % bricksPerAxis, ...).
class SdfGridGeom : public ISdfGeom
{
public:
  void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit,
                 const SdfLeafScene* scene) const override;
  LiteMath::float4 boxMinAndCell;  // the grid's corner and its cells' edge
  uint32_t firstValue = 0, samples = 0, brickCells = 0, bricksPerAxis = 0;
};

// A sparse voxel set: leaf i is voxel firstVoxel + i of the scene's m_voxels (its corner and edge),
// with its 8 corner values at m_values[8 (firstVoxel + i)].
class SdfSVSGeom : public ISdfGeom
{
public:
  void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit,
                 const SdfLeafScene* scene) const override;
  uint32_t firstVoxel = 0, voxelCount = 0;
};

// A sparse brick set: leaf i is brick firstBrick + i of the scene's m_bricks (its corner and voxel
// edge), with its (brickSize + 1)^3 values from m_values[m_brickValues[firstBrick + i]].
class SdfSBSGeom : public ISdfGeom
{
public:
  void Intersect(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit,
                 const SdfLeafScene* scene) const override;
  uint32_t firstBrick = 0, brickCount = 0, brickSize = 0;
};

struct ISdfScene
{
  virtual ~ISdfScene() = default;
  virtual CRT_Hit RayQuery_NearestHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) = 0;
};

// Fields side by side, each its own geomId, under one binary tree of all their leaves' boxes.
class SdfLeafScene : public ISdfScene
{
public:
  uint32_t AddGrid(const litesdf::SdfGrid& grid, uint32_t brickCells);
  uint32_t AddSVS(const litesdf::SdfSVS& svs);  // 4 bytes per value
  uint32_t AddSBS(const litesdf::SdfSBS& sbs);  // 4 bytes per value
  void Commit();                                // builds the tree
  CRT_Hit RayQuery_NearestHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) override;

  // Host only: the boxes of field geomId's leaves, in the order of info.aabbId.
  std::vector<CRT_AABB> LeafBoxes(uint32_t geomId) const;

  // The first hit of the ray with the cells of a brick of n^3 cells of edge `cell` from `corner`,
  // whose corner values are m_values[first + x + y * strideY + z * strideZ], within [t0, t1].
  litesdf::SdfHit MarchBrick(LiteMath::float3 corner, float cell, int n, uint32_t first, uint32_t strideY, uint32_t strideZ,
                             LiteMath::float3 org, LiteMath::float3 dir, float t0, float t1) const;

  std::vector<std::shared_ptr<ISdfGeom>> m_geom;
  std::vector<float> m_values;              // grids' samples and SBS bricks' values
  std::vector<float> m_voxelValues;         // SVS voxels: 8 corner values each
  std::vector<LiteMath::float4> m_voxels;   // SVS voxels: corner, edge
  std::vector<LiteMath::float4> m_bricks;   // SBS bricks: corner, voxel edge
  std::vector<uint32_t> m_brickValues;      // SBS bricks: their first value in m_values
  // The tree, depth first: node i has the box [m_nodeMin[i], m_nodeMax[i]] (xyz). An inner node's
  // children are i + 1 and m_nodeRight[i]; a leaf node has m_nodeLeaf[i] = 1 + its leaf's index in
  // m_leafIds, (geomId, aabbId); an inner node has 0 there.
  std::vector<LiteMath::float4> m_nodeMin, m_nodeMax;
  std::vector<uint32_t> m_nodeRight, m_nodeLeaf;
  std::vector<LiteMath::uint2> m_leafIds;

private:
  struct Leaf
  {
    CRT_AABB box;
    uint32_t geomId, aabbId;
  };
  uint32_t Build(std::vector<Leaf>& leaves, size_t begin, size_t end);
};

class SdfLeafTracer
{
public:
  SdfLeafTracer() = default;
  virtual ~SdfLeafTracer() = default;
  void SetScene(std::shared_ptr<ISdfScene> scene) { m_scene = std::move(scene); }
  // hits[i]: the nearest field along the ray from origins[i] (xyz; w: near) in direction dirs[i] (xyz; w: far).
  virtual void Trace(int n, [[crossrt::size("n")]] const LiteMath::float4* origins, [[crossrt::size("n")]] const LiteMath::float4* dirs,
                     [[crossrt::size("n")]] CRT_Hit* hits);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Trace(int n, const LiteMath::float4* origins, const LiteMath::float4* dirs, CRT_Hit* hits);
  std::shared_ptr<ISdfScene> m_scene;
};
