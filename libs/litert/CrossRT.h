// CrossRT ray query interface: a two-level scene (meshes + instances) with nearest/any hit
// queries. Kernels call RayQuery_* on the CPU; the GPU backend maps them to ray queries.
#pragma once

#include "LiteMath.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

// Result of RayQuery_NearestHit. A miss has primId == instId == geomId == 0xFFFFFFFF and t set to
// the ray's tmax.
struct CRT_Hit
{
  float    t;         // ray parameter of the hit
  uint32_t primId;    // triangle index within the geometry
  uint32_t instId;    // id returned by AddInstance
  uint32_t geomId;    // id returned by AddGeom_Triangles3f
  float    coords[4]; // [0], [1]: barycentrics u, v (Embree convention: p = (1-u-v)*v0 + u*v1 + v*v2); [2], [3]: 0
};

// Build flags: the low two bits select BVH quality; BUILD_REFIT marks geometry that will be updated.
enum BuildOptions
{
  BUILD_LOW    = 0,
  BUILD_MEDIUM = 1,
  BUILD_HIGH   = 2,
  BUILD_REFIT  = 4,
};

// A committed scene as plain arrays: what a backend that builds its own acceleration structures
// needs (a translated class tracing on ray tracing hardware builds them from this).
struct CRT_SceneExport
{
  // Mesh g (the id AddGeom_Triangles3f returned): 9 floats per triangle, corners v0, v1, v2,
  // triangle i (the primId a hit reports) at [9 i, 9 i + 9).
  std::vector<std::vector<float>> meshTriangles;
  struct Instance
  {
    uint32_t geomId;
    float toWorldRows[12];  // rows 0-2 of the object-to-world matrix
  };
  std::vector<Instance> instances;  // instance i is the id AddInstance returned
};

struct ISceneObject
{
  virtual ~ISceneObject() = default;

  virtual const char* Name() const = 0;

  // Removes all meshes. Instances reference meshes, so this also clears the scene (ClearScene).
  virtual void ClearGeom() = 0;

  // Copies a triangle mesh (indNum/3 triangles); vertex i is read at vpos3f + i*vByteStride bytes.
  // Returns the geometry id (0, 1, 2, ... in call order). Throws std::invalid_argument on bad input.
  virtual uint32_t AddGeom_Triangles3f(const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum,
                                       uint32_t flags = BUILD_HIGH, size_t vByteStride = 3 * sizeof(float)) = 0;
  // Replaces the data of an existing mesh; call CommitScene afterwards.
  virtual void UpdateGeom_Triangles3f(uint32_t geomId, const float* vpos3f, size_t vertNum, const uint32_t* triIndices,
                                      size_t indNum, uint32_t flags = BUILD_HIGH,
                                      size_t vByteStride = 3 * sizeof(float)) = 0;

  // Removes all instances (meshes stay).
  virtual void ClearScene() = 0;
  // Places mesh geomId with an object-to-world matrix. Returns the instance id (0, 1, 2, ...).
  virtual uint32_t AddInstance(uint32_t geomId, const LiteMath::float4x4& matrix) = 0;
  virtual void     UpdateInstance(uint32_t instanceId, const LiteMath::float4x4& matrix) = 0;
  // Builds the top-level structure; queries before the first commit (or after a change without
  // a new commit) miss.
  virtual void CommitScene(uint32_t options = BUILD_HIGH) = 0;

  // posAndNear = origin xyz + tmin in w; dirAndFar = direction xyz + tmax in w. Thread-safe:
  // any number of threads may query concurrently (but not while the scene is being modified).
  // Rays with NaN/inf components, a zero direction or tmin >= tmax miss.
  virtual CRT_Hit RayQuery_NearestHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) = 0;
  virtual bool    RayQuery_AnyHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) = 0;

  // The scene as last committed (no instances before the first CommitScene or after a change
  // without a new one, so that every query misses, as RayQuery_* do). Implementations that do not
  // keep their input return false; the default does.
  virtual bool ExportScene(CRT_SceneExport& out) const
  {
    (void)out;
    return false;
  }
};

// Creates a scene implementation by name ("embree"; case-insensitive). Throws std::invalid_argument
// listing the known names for an unknown one, std::runtime_error if the backend fails to start.
std::shared_ptr<ISceneObject> CreateSceneRT(const char* name);
