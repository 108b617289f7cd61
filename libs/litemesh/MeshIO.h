// Triangle meshes from files: OFF, PLY and OBJ, also gzipped (.ply.gz), read through the Open Asset
// Import Library. Polygons are triangulated and node transforms applied, so every format arrives
// as one indexed triangle list.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

struct TriangleMesh
{
  std::vector<float> positions;   // xyz per vertex
  std::vector<uint32_t> indices;  // 3 per triangle
  size_t VertexCount() const { return positions.size() / 3; }
  size_t TriangleCount() const { return indices.size() / 3; }
};

// Throws std::runtime_error naming the file and the reason (missing, unreadable, not a mesh, no
// triangles).
TriangleMesh LoadMesh(const std::string& path);
