// What the BVH benchmarks share (bench_lbvh, bench_first_build): a mesh's triangle boxes, the
// builders' input, and Embree's build of it, the peer they are measured against.
#pragma once
#include "LiteMath.h"
#include "MeshIO.h"

#include <embree3/rtcore.h>

#include <chrono>
#include <string>
#include <vector>

inline std::vector<LiteMath::Box4f> TriangleBoxes(const TriangleMesh& mesh)
{
  std::vector<LiteMath::Box4f> boxes(mesh.TriangleCount());
  for (size_t t = 0; t < boxes.size(); ++t)
    for (int k = 0; k < 3; ++k)
    {
      const uint32_t v = mesh.indices[3 * t + k];
      boxes[t].include(LiteMath::float4(mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2], 0.0f));
    }
  return boxes;
}

// Embree over one mesh, on a device made with `config` (rtcNewDevice's: "isa=avx2" caps the SIMD
// width Embree picks; empty for its defaults).
struct EmbreeMesh
{
  explicit EmbreeMesh(const std::string& config = "") : device(rtcNewDevice(config.empty() ? nullptr : config.c_str())) {}
  EmbreeMesh(const EmbreeMesh&) = delete;
  EmbreeMesh& operator=(const EmbreeMesh&) = delete;

  // Builds the mesh with the quality given; returns the time of the build (its commit), ms.
  double Build(const TriangleMesh& mesh, RTCBuildQuality quality)
  {
    if (scene) rtcReleaseScene(scene);
    const auto t0 = std::chrono::steady_clock::now();
    scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(scene, quality);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh.positions.data(), 0, 12, mesh.VertexCount());
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.indices.data(), 0, 12, mesh.TriangleCount());
    rtcSetGeometryBuildQuality(geom, quality);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }

  ~EmbreeMesh()
  {
    if (scene) rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }

  RTCDevice device;
  RTCScene scene = nullptr;
};
