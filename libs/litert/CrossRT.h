// CrossRT ray query interface: a two-level scene (meshes, boxes of custom primitives, instances,
// moving instances) with nearest/any hit queries, as the paper's CrossRT.h declares it. Kernels call
// RayQuery_* on the CPU; the GPU backend maps them to ray queries.
#pragma once

#include "LiteMath.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace litesdf {  // signed distance fields (libs/litesdf), as scenes take them
struct SdfGrid;
struct SdfSVS;
struct SdfSBS;
}  // namespace litesdf

// Result of RayQuery_NearestHit. A miss has primId == instId == geomId == 0xFFFFFFFF and t set to
// the ray's tmax. A hit on box geometry has CRT_GEOM_MASK_AABB_BIT in geomId. A hit on a signed
// distance field has its surface normal in coords[0..2] (object space, unit length; 0 where the
// interpolant has no gradient, as at a start inside among equal values) and the voxel (SVS) or brick
// (SBS) hit as primId (0 on a dense grid).
struct CRT_Hit
{
  float    t;         // ray parameter of the hit
  uint32_t primId;    // triangle index within the geometry
  uint32_t instId;    // id returned by AddInstance
  uint32_t geomId;    // id returned by AddGeom_Triangles3f
  float    coords[4]; // triangles: [0], [1] barycentrics u, v (Embree convention: p = (1-u-v)*v0 + u*v1 + v*v2); [2], [3]: 0
};

// Build flags, with the paper's values: a quality, BUILD_REFIT for geometry that will be updated,
// MOTION_BLUR for scenes with motion instances.
enum BuildOptions
{
  NONE                   = 0x00000000,
  BUILD_LOW              = 0x00000001,
  BUILD_MEDIUM           = 0x00000002,
  BUILD_HIGH             = 0x00000004,
  BUILD_REFIT            = 0x00000008,
  MOTION_BLUR            = 0x00000010,
  BUILD_NOW              = 0x00000020,
  BUILD_OPTIONS_MAX_ENUM = 0x7FFFFFFF,
};

// Box geometry (custom primitives): AddGeom_AABB returns its id with this bit set, and a hit on it
// reports that id; the other mask takes the bit off. AddInstance accepts either.
static constexpr uint32_t CRT_GEOM_MASK_AABB_BIT    = 0x80000000u;
static constexpr uint32_t CRT_GEOM_MASK_AABB_BIT_RM = 0x7fffffffu;

// An axis-aligned box of a custom primitive (w components unused).
struct CRT_AABB
{
  LiteMath::float4 boxMin;
  LiteMath::float4 boxMax;
};

// What a custom primitive's intersection is told about the box a ray reached.
struct CRT_LeafInfo
{
  uint32_t aabbId;  // the box, among its geometry's
  uint32_t primId;  // the primitive it bounds
  uint32_t instId;  // the instance
  uint32_t geomId;  // the geometry (with CRT_GEOM_MASK_AABB_BIT)
  uint32_t rayxId;  // the ray (e.g. its pixel)
  uint32_t rayyId;
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

  // The implementation's name, for messages (LiteRT's older scenes do not name themselves).
  virtual const char* Name() const { return "ISceneObject"; }

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

  // Boxes as a geometry, for custom primitives (paper 3.10): boxNumber boxes, a primitive per
  // boxNumber / customPrimCount of them (one each without customPrimPtrs); typeId names the kind of
  // primitive, buildFlags (BUILD_*) how well to build the boxes' tree, a hint an implementation may
  // ignore. Returns the geometry id with CRT_GEOM_MASK_AABB_BIT set. Unless a subclass intersects
  // the primitives itself, a ray hits a box where it enters it (or at tmin, from inside): the hit's
  // primId is the primitive, its geomId the id returned, coords are 0. Implementations without box
  // geometry throw std::runtime_error. An implementation overrides these two; the two without
  // buildFlags below (LiteRT's earlier form) call them with BUILD_HIGH.
  virtual uint32_t AddGeom_AABB(uint32_t typeId, const CRT_AABB* boxMinMaxF8, size_t boxNumber, uint32_t buildFlags, void** customPrimPtrs,
                                size_t customPrimCount)
  {
    (void)typeId, (void)boxMinMaxF8, (void)boxNumber, (void)buildFlags, (void)customPrimPtrs, (void)customPrimCount;
    throw std::runtime_error(std::string(Name()) + ": this ISceneObject has no box geometry (AddGeom_AABB)");
  }
  virtual void UpdateGeom_AABB(uint32_t geomId, uint32_t typeId, const CRT_AABB* boxMinMaxF8, size_t boxNumber, uint32_t buildFlags,
                               void** customPrimPtrs, size_t customPrimCount)
  {
    (void)geomId, (void)typeId, (void)boxMinMaxF8, (void)boxNumber, (void)buildFlags, (void)customPrimPtrs, (void)customPrimCount;
    throw std::runtime_error(std::string(Name()) + ": this ISceneObject has no box geometry (UpdateGeom_AABB)");
  }
  virtual uint32_t AddGeom_AABB(uint32_t typeId, const CRT_AABB* boxMinMaxF8, size_t boxNumber, void** customPrimPtrs = nullptr,
                                size_t customPrimCount = 0)
  {
    return AddGeom_AABB(typeId, boxMinMaxF8, boxNumber, uint32_t(BUILD_HIGH), customPrimPtrs, customPrimCount);
  }
  virtual void UpdateGeom_AABB(uint32_t geomId, uint32_t typeId, const CRT_AABB* boxMinMaxF8, size_t boxNumber, void** customPrimPtrs = nullptr,
                               size_t customPrimCount = 0)
  {
    UpdateGeom_AABB(geomId, typeId, boxMinMaxF8, boxNumber, uint32_t(BUILD_HIGH), customPrimPtrs, customPrimCount);
  }

  // Signed distance fields as geometry (paper 4.2): the surface where the trilinear interpolant of the
  // samples is 0, found per voxel with Newton's method (litesdf/SdfVoxel.h). Copied; placed by
  // AddInstance like meshes. Returns the geometry id. Implementations without SDFs throw
  // std::runtime_error; bad input (no samples, a depth over 10, an unknown value size) is
  // std::invalid_argument.
  virtual uint32_t AddGeom_SdfGrid(const litesdf::SdfGrid& grid, uint32_t flags = BUILD_HIGH)
  {
    (void)grid, (void)flags;
    throw std::runtime_error(std::string(Name()) + ": this ISceneObject has no signed distance fields (AddGeom_SdfGrid)");
  }
  virtual uint32_t AddGeom_SdfSVS(const litesdf::SdfSVS& svs, uint32_t flags = BUILD_HIGH)
  {
    (void)svs, (void)flags;
    throw std::runtime_error(std::string(Name()) + ": this ISceneObject has no signed distance fields (AddGeom_SdfSVS)");
  }
  virtual uint32_t AddGeom_SdfSBS(const litesdf::SdfSBS& sbs, uint32_t flags = BUILD_HIGH)
  {
    (void)sbs, (void)flags;
    throw std::runtime_error(std::string(Name()) + ": this ISceneObject has no signed distance fields (AddGeom_SdfSBS)");
  }

  // Removes all instances (meshes stay).
  virtual void ClearScene() = 0;
  // Places mesh geomId with an object-to-world matrix. Returns the instance id (0, 1, 2, ...).
  virtual uint32_t AddInstance(uint32_t geomId, const LiteMath::float4x4& matrix) = 0;
  virtual void     UpdateInstance(uint32_t instanceId, const LiteMath::float4x4& matrix) = 0;
  // A moving instance: matrixNumber object-to-world matrices at evenly spaced times from 0 to 1,
  // interpolated linearly between them for a ray's time (RayQuery_*Motion). Implementations without
  // motion take one matrix and throw std::runtime_error for more.
  virtual uint32_t AddInstanceMotion(uint32_t geomId, const LiteMath::float4x4* matrices, uint32_t matrixNumber)
  {
    if (matrixNumber == 1) return AddInstance(geomId, matrices[0]);
    throw std::runtime_error(std::string(Name()) + ": this ISceneObject has no motion instances (AddInstanceMotion)");
  }
  // Builds the top-level structure; queries before the first commit (or after a change without
  // a new commit) miss.
  virtual void CommitScene(uint32_t options = BUILD_HIGH) = 0;

  // posAndNear = origin xyz + tmin in w; dirAndFar = direction xyz + tmax in w. Thread-safe:
  // any number of threads may query concurrently (but not while the scene is being modified).
  // Rays with NaN/inf components, a zero direction or tmin >= tmax miss.
  virtual CRT_Hit RayQuery_NearestHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) = 0;
  virtual bool    RayQuery_AnyHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) = 0;
  // The same at a time in [0, 1], where motion instances are (a scene without them: the same as above).
  virtual CRT_Hit RayQuery_NearestHitMotion(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, float time)
  {
    (void)time;
    return RayQuery_NearestHit(posAndNear, dirAndFar);
  }
  virtual bool RayQuery_AnyHitMotion(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, float time = 0.0f)
  {
    (void)time;
    return RayQuery_AnyHit(posAndNear, dirAndFar);
  }
  // The implementation behind a wrapper (the paper's API; this one is its own).
  virtual ISceneObject* UnderlyingImpl(uint32_t implId)
  {
    (void)implId;
    return this;
  }

  // The scene as last committed (no instances before the first CommitScene or after a change
  // without a new one, so that every query misses, as RayQuery_* do). Implementations that do not
  // keep their input return false; the default does.
  virtual bool ExportScene(CRT_SceneExport& out) const
  {
    (void)out;
    return false;
  }
};

// Creates a scene implementation by name, case-insensitive: "embree" (Embree 3), "lbvh" and "sah"
// (BVHScene with those builders), and the paper's names for the same ("BVH2Common", "BVH4Common":
// sah). Throws std::invalid_argument listing the known names for an unknown one, std::runtime_error
// if the backend fails to start. As in the paper's API, the caller owns the scene and deletes it with
// DeleteSceneRT: std::shared_ptr<ISceneObject>(CreateSceneRT("sah"), DeleteSceneRT).
ISceneObject* CreateSceneRT(const char* implName);
void DeleteSceneRT(ISceneObject* scene);
// Owned by a shared_ptr: std::shared_ptr<ISceneObject>(CreateSceneRT(implName), DeleteSceneRT).
inline std::shared_ptr<ISceneObject> MakeSceneRT(const char* implName)
{
  return std::shared_ptr<ISceneObject>(CreateSceneRT(implName), DeleteSceneRT);
}
// LiteRT's form: implementation, builder ("lbvh", "sah"; others, or "", the implementation's own) and
// node layout (ignored: BVHScene has one), shared.
std::shared_ptr<ISceneObject> CreateSceneRT(const char* implName, const char* buildName, const char* layoutName);
