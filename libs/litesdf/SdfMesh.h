// The signed distance to a triangle mesh, as an ISdf the grid, SVS and SBS builders take.
// The distance is exact: the closest point over a BVH of the triangles (litebvh's SAH builder).
// The sign has two sources (SdfSign):
//   - the angle-weighted pseudo-normal of the feature (face, edge or vertex) the closest point lies
//     on (Bærentzen and Aanæs 2005): exact and cheap, and robust at edges and vertices, but only for
//     a closed 2-manifold, every edge shared by exactly two triangles;
//   - the generalised winding number (Jacobson, Kavan and Sorkine-Hornung 2013), inside where it is
//     at least 1/2: robust to holes, non-manifold edges and overlapping parts, as scanned meshes have
//     them. It is evaluated hierarchically over the same BVH (Barill et al. 2018, "Fast Winding
//     Numbers"): a cluster far enough from p counts as one dipole, its area-weighted normal at its
//     area-weighted centre; near clusters are summed triangle by triangle.
// Triangles are counter-clockwise seen from outside.
#pragma once
#include "BVHNode.h"
#include "SdfAnalytic.h"

#include <cstdint>
#include <vector>

namespace litesdf {

// xyz positions (3 floats per vertex) moved and scaled uniformly so that their bounding box is
// centred at the origin and its longest side is 2 * halfExtent.
std::vector<float3> FitIntoCube(const std::vector<float>& positions, float halfExtent);

// Where SdfMesh::Distance takes its sign from.
enum class SdfSign {
  Auto,           // PseudoNormal for a closed 2-manifold, WindingNumber for any other mesh
  PseudoNormal,   // the closest feature's angle-weighted pseudo-normal
  WindingNumber,  // the fast winding number at least 1/2
};

class SdfMesh : public ISdf {
public:
  // `vertices` as float3; `indices` three per triangle.
  SdfMesh(std::vector<float3> vertices, std::vector<uint32_t> indices, SdfSign sign = SdfSign::Auto);
  float Distance(float3 p) const override;
  float UnsignedDistance(float3 p) const override;

  // The generalised winding number of the mesh at p: 1 inside a closed mesh, 0 outside, fractional
  // near holes (the sum of the triangles' signed solid angles over 4 pi), exactly, triangle by
  // triangle. For tests of the sign.
  float WindingNumber(float3 p) const;
  // The same, hierarchically (what SdfSign::WindingNumber uses): within about 0.01 of it away
  // from the surface, in time logarithmic in the triangles.
  float FastWindingNumber(float3 p) const;

  // The sign source Auto resolved to, and why: the edges not shared by exactly two triangles
  // (holes' borders and non-manifold edges). Pseudo-normals are exact only when there are none.
  SdfSign Sign() const { return m_sign; }
  size_t OpenOrNonManifoldEdges() const { return m_badEdges; }

  size_t TriangleCount() const { return m_indices.size() / 3; }
  float3 BoxMin() const { return m_boxMin; }
  float3 BoxMax() const { return m_boxMax; }

private:
  float NearestSquared(float3 p, float3& nearest, float3& pseudoNormal) const;

  // A BVH node's triangles seen from afar: their area-weighted normal (half the sum of the cross
  // products) at their area-weighted centre, and the radius of a ball around it holding them.
  struct Cluster {
    float3 center;
    float radius;
    float3 areaNormal;
  };

  std::vector<float3> m_vertices;
  std::vector<uint32_t> m_indices;
  BVHTree m_bvh;
  std::vector<float3> m_faceNormals;    // per triangle
  std::vector<float3> m_vertexNormals;  // angle-weighted, per vertex
  std::vector<float3> m_edgeNormals;    // per triangle edge (v0v1, v1v2, v2v0): its faces' sum
  std::vector<Cluster> m_clusters;      // per BVH node; built for SdfSign::WindingNumber only
  SdfSign m_sign = SdfSign::PseudoNormal;
  size_t m_badEdges = 0;
  float3 m_boxMin, m_boxMax;
};

}  // namespace litesdf
