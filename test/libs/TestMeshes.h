// Meshes built in code for the ray tracing tests: closed spheres (every edge shared by exactly
// two triangles, every vertex by several), so rays through edges and vertices are easy to aim.
#pragma once
#include "CrossRT.h"
#include "LiteMath.h"
#include "MeshIO.h"

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

inline LiteMath::float3 Vertex(const TriangleMesh& mesh, uint32_t i)
{
  return {mesh.positions[3 * i], mesh.positions[3 * i + 1], mesh.positions[3 * i + 2]};
}

// Triangle prim's (unnormalized) normal, by its winding.
inline LiteMath::float3 TriangleNormal(const TriangleMesh& mesh, uint32_t prim)
{
  const LiteMath::float3 a = Vertex(mesh, mesh.indices[3 * prim]), b = Vertex(mesh, mesh.indices[3 * prim + 1]),
                         c = Vertex(mesh, mesh.indices[3 * prim + 2]);
  return cross(b - a, c - a);
}

// An octahedron subdivided `levels` times and pushed onto the sphere |p - center| = radius:
// 8 * 4^levels triangles, closed and consistently wound.
inline TriangleMesh Sphere(int levels, LiteMath::float3 center = LiteMath::float3(0.0f), float radius = 1.0f)
{
  std::vector<LiteMath::float3> points = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<uint32_t> tris = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  for (int l = 0; l < levels; ++l)
  {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto key = std::minmax(a, b);
      auto it = midpoints.find(key);
      if (it != midpoints.end()) return it->second;
      points.push_back(normalize(points[a] + points[b]));
      return midpoints[key] = uint32_t(points.size() - 1);
    };
    std::vector<uint32_t> next;
    for (size_t t = 0; t < tris.size(); t += 3)
    {
      const uint32_t a = tris[t], b = tris[t + 1], c = tris[t + 2];
      const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.insert(next.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
    }
    tris = std::move(next);
  }
  TriangleMesh mesh;
  for (auto p : points)
  {
    const LiteMath::float3 q = center + radius * normalize(p);
    mesh.positions.insert(mesh.positions.end(), {q.x, q.y, q.z});
  }
  mesh.indices = std::move(tris);
  return mesh;
}

// A sphere with bumps: closed like the sphere, but not convex, so lines cross it many times.
inline TriangleMesh BumpySphere(int levels)
{
  TriangleMesh mesh = Sphere(levels);
  for (size_t i = 0; i < mesh.VertexCount(); ++i)
  {
    LiteMath::float3 p = Vertex(mesh, uint32_t(i));
    p = p * (1.0f + 0.3f * std::sin(5.0f * p.x) * std::sin(5.0f * p.y));
    mesh.positions[3 * i] = p.x, mesh.positions[3 * i + 1] = p.y, mesh.positions[3 * i + 2] = p.z;
  }
  return mesh;
}

// The cube [-1, 1]^3: 12 triangles, wound outwards.
inline TriangleMesh Cube()
{
  TriangleMesh cube;
  cube.positions = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
  cube.indices = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 3, 6, 2, 3, 7, 6, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};
  return cube;
}

// The mesh with `m` applied to its vertices in float, as a scene far away or scaled would be stored.
inline TriangleMesh Transformed(TriangleMesh mesh, const LiteMath::float4x4& m)
{
  for (size_t i = 0; i < mesh.VertexCount(); ++i)
  {
    const LiteMath::float3 p = LiteMath::to_float3(m * LiteMath::float4(mesh.positions[3 * i], mesh.positions[3 * i + 1], mesh.positions[3 * i + 2], 1.0f));
    mesh.positions[3 * i] = p.x, mesh.positions[3 * i + 1] = p.y, mesh.positions[3 * i + 2] = p.z;
  }
  return mesh;
}

// A committed scene of implementation `impl` holding `mesh` once per instance matrix.
inline std::shared_ptr<ISceneObject> SceneOf(const char* impl, const TriangleMesh& mesh,
                                             const std::vector<LiteMath::float4x4>& instances = {LiteMath::float4x4()})
{
  auto scene = MakeSceneRT(impl);
  const uint32_t geom = scene->AddGeom_Triangles3f(mesh.positions.data(), mesh.VertexCount(), mesh.indices.data(), mesh.indices.size());
  for (const LiteMath::float4x4& m : instances)
    scene->AddInstance(geom, m);
  scene->CommitScene();
  return scene;
}
