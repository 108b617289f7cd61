// The signed distance to a closed triangle mesh, as an ISdf the grid, SVS and SBS builders take.
// The distance is exact: the closest point over a BVH of the triangles (litebvh's SAH builder). The
// sign is robust at edges and vertices: the side of the angle-weighted pseudo-normal of the feature
// (face, edge or vertex) the closest point lies on (Bærentzen and Aanæs 2005). The mesh must be
// closed and consistently oriented (counter-clockwise seen from outside).
#pragma once
#include "BVHNode.h"
#include "SdfAnalytic.h"

#include <cstdint>
#include <vector>

namespace litesdf {

// xyz positions (3 floats per vertex) moved and scaled uniformly so that their bounding box is
// centred at the origin and its longest side is 2 * halfExtent.
std::vector<float3> FitIntoCube(const std::vector<float>& positions, float halfExtent);

class SdfMesh : public ISdf {
public:
  // `vertices` as float3; `indices` three per triangle.
  SdfMesh(std::vector<float3> vertices, std::vector<uint32_t> indices);
  float Distance(float3 p) const override;

  // The generalised winding number of the mesh at p: 1 inside a closed mesh, 0 outside (the sum of
  // the triangles' signed solid angles over 4 pi). For tests of the sign.
  float WindingNumber(float3 p) const;

  size_t TriangleCount() const { return m_indices.size() / 3; }
  float3 BoxMin() const { return m_boxMin; }
  float3 BoxMax() const { return m_boxMax; }

private:
  std::vector<float3> m_vertices;
  std::vector<uint32_t> m_indices;
  BVHTree m_bvh;
  std::vector<float3> m_faceNormals;    // per triangle
  std::vector<float3> m_vertexNormals;  // angle-weighted, per vertex
  std::vector<float3> m_edgeNormals;    // per triangle edge (v0v1, v1v2, v2v0): the two faces' sum
  float3 m_boxMin, m_boxMax;
};

}  // namespace litesdf
