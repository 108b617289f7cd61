// Mesh files through litemesh (OFF, OBJ, gzipped PLY; bad files give clear errors), and the real
// closed bunny of ../shared/DATA.md traced from inside by CrossRT's BVHs. The bunny comes from
// scripts/fetch-meshes.sh (run by scripts/run-tests.sh); without it that test says so and skips.
#include <catch2/catch.hpp>

#include "CrossRT.h"
#include "MeshIO.h"
#include "TestMeshes.h"

#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

using namespace LiteMath;
namespace fs = std::filesystem;

namespace {

std::string MeshDir()
{
  const char* dir = std::getenv("CROSSRT_MESH_DIR");
  return dir ? dir : CROSSRT_SOURCE_DIR "/build/data/meshes";
}

struct TempDir
{
  fs::path path = fs::temp_directory_path() / ("crossrt-meshes-" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { std::error_code ec; fs::remove_all(path, ec); }
};

const char* kTetrahedronOff = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

}  // namespace

TEST_CASE("LoadMesh reads OFF, OBJ with quads and gzipped PLY", "[litemesh]")
{
  TempDir tmp;
  std::ofstream(tmp.path / "tetra.off") << kTetrahedronOff;
  const TriangleMesh off = LoadMesh((tmp.path / "tetra.off").string());
  REQUIRE(off.TriangleCount() == 4);

  std::ofstream(tmp.path / "quad.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
  const TriangleMesh obj = LoadMesh((tmp.path / "quad.obj").string());
  REQUIRE(obj.TriangleCount() == 2);  // the quad, triangulated

  const std::string ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                          "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n2 0 0\n0 3 0\n3 0 1 2\n";
  gzFile gz = gzopen((tmp.path / "tri.ply.gz").string().c_str(), "wb");
  REQUIRE(gz != nullptr);
  gzwrite(gz, ply.data(), unsigned(ply.size()));
  gzclose(gz);
  const TriangleMesh plyGz = LoadMesh((tmp.path / "tri.ply.gz").string());
  REQUIRE(plyGz.TriangleCount() == 1);
  float maxY = 0.0f;
  for (size_t v = 0; v < plyGz.VertexCount(); ++v) maxY = std::max(maxY, plyGz.positions[3 * v + 1]);
  REQUIRE(maxY == 3.0f);
}

TEST_CASE("LoadMesh names the file and the reason when it cannot read a mesh", "[litemesh]")
{
  TempDir tmp;
  const std::string missing = (tmp.path / "missing.off").string();
  REQUIRE_THROWS_WITH(LoadMesh(missing), Catch::Contains(missing) && Catch::Contains("no such file"));
  std::ofstream(tmp.path / "garbage.ply") << "this is not a mesh\n";
  REQUIRE_THROWS_WITH(LoadMesh((tmp.path / "garbage.ply").string()), Catch::Contains("garbage.ply"));
  std::ofstream(tmp.path / "broken.ply.gz") << "not gzip data at all";
  REQUIRE_THROWS_WITH(LoadMesh((tmp.path / "broken.ply.gz").string()), Catch::Contains("broken.ply.gz"));
}

TEST_CASE("Rays from random points inside the closed bunny all hit it, and leave it last", "[litemesh][bvh][extremes]")
{
  const std::string path = MeshDir() + "/bunny00.off";
  if (!fs::exists(path))
  {
    WARN("skipped: " << path << " is missing (scripts/fetch-meshes.sh fetches it)");
    return;
  }
  const TriangleMesh mesh = LoadMesh(path);
  REQUIRE(mesh.TriangleCount() > 50000);
  float3 lo(1e30f), hi(-1e30f);
  for (size_t v = 0; v < mesh.VertexCount(); ++v) lo = min(lo, Vertex(mesh, uint32_t(v))), hi = max(hi, Vertex(mesh, uint32_t(v)));
  // Orientation: the signed volume tells whether triangle normals point out.
  double volume = 0.0;
  for (size_t t = 0; t < mesh.indices.size(); t += 3)
    volume += dot(Vertex(mesh, mesh.indices[t]), cross(Vertex(mesh, mesh.indices[t + 1]), Vertex(mesh, mesh.indices[t + 2])));
  const float outward = volume > 0.0 ? 1.0f : -1.0f;

  auto reference = MakeSceneRT("embree");
  reference->AddInstance(reference->AddGeom_Triangles3f(mesh.positions.data(), mesh.VertexCount(), mesh.indices.data(), mesh.indices.size()), float4x4());
  reference->CommitScene();
  for (const char* impl : {"lbvh", "sah"})
  {
    INFO(impl);
    auto scene = MakeSceneRT(impl);
    scene->AddInstance(scene->AddGeom_Triangles3f(mesh.positions.data(), mesh.VertexCount(), mesh.indices.data(), mesh.indices.size()), float4x4());
    scene->CommitScene();
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f), s(-1.0f, 1.0f);
    size_t points = 0, rays = 0, misses = 0, notLeavingLast = 0;
    while (points < 200)
    {
      const float3 p = lo + (hi - lo) * float3(u(rng), u(rng), u(rng));
      // Inside: Embree's first hit along +x and along -y both face outward.
      bool inside = true;
      for (float3 d : {float3(1, 0, 0), float3(0, -1, 0)})
      {
        const CRT_Hit h = reference->RayQuery_NearestHit(float4(p.x, p.y, p.z, 0.0f), float4(d.x, d.y, d.z, 1e30f));
        if (h.primId == 0xFFFFFFFFu) { inside = false; break; }
        inside = inside && outward * dot(TriangleNormal(mesh, h.primId), d) > 0.0f;
      }
      if (!inside) continue;
      ++points;
      for (int r = 0; r < 50; ++r)
      {
        // Random directions, and directions exactly at vertices (rays through shared vertices).
        const float3 target = r % 2 ? Vertex(mesh, mesh.indices[rng() % mesh.indices.size()]) : p + float3(s(rng), s(rng), s(rng));
        const float3 d = target - p;
        ++rays;
        float tnear = 0.0f;
        int lastFacing = 0, hits = 0;
        float lastT = 0.0f;
        for (;;)
        {
          const CRT_Hit h = scene->RayQuery_NearestHit(float4(p.x, p.y, p.z, tnear), float4(d.x, d.y, d.z, 1e30f));
          if (h.primId == 0xFFFFFFFFu) break;
          lastFacing = outward * dot(TriangleNormal(mesh, h.primId), d) > 0.0f ? 1 : -1;
          ++hits;
          lastT = h.t;
          tnear = std::nextafter(h.t, 1e30f);
        }
        misses += hits == 0;
        // The last hit leaves the mesh, except where a ray aimed at a vertex (t = 1) only touches
        // the surface there, at a silhouette: any triangle of the vertex's fan may be reported.
        const bool touchAtTarget = r % 2 == 1 && std::fabs(lastT - 1.0f) < 1e-5f;
        notLeavingLast += hits > 0 && lastFacing != 1 && !touchAtTarget;
      }
    }
    REQUIRE(rays == 10000);
    REQUIRE(misses == 0);
    REQUIRE(notLeavingLast == 0);
  }
}
