// Embree 3 implementation of ISceneObject.
//
// Layout: one RTCScene per mesh (holding a single triangle geometry with id 0, or for box geometry
// and signed distance fields a user geometry: EmbreeSdf.h) and a top-level RTCScene whose geometries are INSTANCE geometries
// referencing the mesh scenes, with a time step per matrix of a moving instance. Instance i is
// attached with geometry id i, so Embree's instID is directly our instance id.
#include "CrossRT.h"
#include "EmbreeSdf.h"
#include "SceneInput.h"
#include "SdfStructures.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
constexpr uint32_t CRT_INVALID_ID = 0xFFFFFFFFu;

void embreeErrorCallback(void* /*userPtr*/, RTCError code, const char* str)
{
  std::fprintf(stderr, "[EmbreeRT] Embree error %d: %s\n", int(code), str ? str : "(no message)");
}

RTCBuildQuality qualityFromFlags(uint32_t flags)
{
  if (flags & BUILD_HIGH) return RTC_BUILD_QUALITY_HIGH;
  if (flags & BUILD_MEDIUM) return RTC_BUILD_QUALITY_MEDIUM;
  if (flags & BUILD_LOW) return RTC_BUILD_QUALITY_LOW;
  return RTC_BUILD_QUALITY_MEDIUM;  // NONE
}

// Box geometry: the boxes of a user geometry; a ray hits a box where it enters it (CrossRT.h).
struct BoxData
{
  std::vector<CRT_AABB> boxes;
  uint32_t boxesPerPrim = 1;
};

void boxBounds(const RTCBoundsFunctionArguments* args)
{
  const CRT_AABB& b = static_cast<const BoxData*>(args->geometryUserPtr)->boxes[args->primID];
  args->bounds_o->lower_x = b.boxMin.x;
  args->bounds_o->lower_y = b.boxMin.y;
  args->bounds_o->lower_z = b.boxMin.z;
  args->bounds_o->upper_x = b.boxMax.x;
  args->bounds_o->upper_y = b.boxMax.y;
  args->bounds_o->upper_z = b.boxMax.z;
}

// Where a ray enters the box, in [tnear, tfar] (tnear from inside); false when it misses.
bool boxEntry(const CRT_AABB& b, const float org[3], const float dir[3], float tnear, float tfar, float& t)
{
  const float lo[3] = {b.boxMin.x, b.boxMin.y, b.boxMin.z}, hi[3] = {b.boxMax.x, b.boxMax.y, b.boxMax.z};
  for (int a = 0; a < 3; a++)
  {
    if (dir[a] == 0.0f)
    {
      if (org[a] < lo[a] || org[a] > hi[a])
        return false;
      continue;
    }
    const float t0 = (lo[a] - org[a]) / dir[a], t1 = (hi[a] - org[a]) / dir[a];
    tnear = std::max(tnear, std::min(t0, t1));
    tfar = std::min(tfar, std::max(t0, t1));
  }
  t = tnear;
  return tnear <= tfar;
}

void boxIntersect(const RTCIntersectFunctionNArguments* args)
{
  const BoxData& data = *static_cast<const BoxData*>(args->geometryUserPtr);
  RTCRayHitN* rayHit = args->rayhit;
  RTCRayN* ray = RTCRayHitN_RayN(rayHit, args->N);
  RTCHitN* hit = RTCRayHitN_HitN(rayHit, args->N);
  for (unsigned i = 0; i < args->N; i++)
  {
    if (args->valid[i] == 0)
      continue;
    const float org[3] = {RTCRayN_org_x(ray, args->N, i), RTCRayN_org_y(ray, args->N, i), RTCRayN_org_z(ray, args->N, i)};
    const float dir[3] = {RTCRayN_dir_x(ray, args->N, i), RTCRayN_dir_y(ray, args->N, i), RTCRayN_dir_z(ray, args->N, i)};
    float t;
    if (!boxEntry(data.boxes[args->primID], org, dir, RTCRayN_tnear(ray, args->N, i), RTCRayN_tfar(ray, args->N, i), t))
      continue;
    RTCRayN_tfar(ray, args->N, i) = t;
    RTCHitN_u(hit, args->N, i) = 0.0f;
    RTCHitN_v(hit, args->N, i) = 0.0f;
    RTCHitN_Ng_x(hit, args->N, i) = 0.0f;
    RTCHitN_Ng_y(hit, args->N, i) = 0.0f;
    RTCHitN_Ng_z(hit, args->N, i) = 1.0f;
    RTCHitN_geomID(hit, args->N, i) = args->geomID;
    RTCHitN_primID(hit, args->N, i) = args->primID;
    RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
  }
}

void boxOccluded(const RTCOccludedFunctionNArguments* args)
{
  const BoxData& data = *static_cast<const BoxData*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; i++)
  {
    if (args->valid[i] == 0)
      continue;
    const float org[3] = {RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i), RTCRayN_org_z(args->ray, args->N, i)};
    const float dir[3] = {RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i), RTCRayN_dir_z(args->ray, args->N, i)};
    float t;
    if (boxEntry(data.boxes[args->primID], org, dir, RTCRayN_tnear(args->ray, args->N, i), RTCRayN_tfar(args->ray, args->N, i), t))
      RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();  // Embree's "occluded"
  }
}

// Validated ray in Embree's form; `valid == false` means the query must report a miss.
struct PreparedRay
{
  RTCRay ray;
  bool   valid;
};

PreparedRay prepareRay(const LiteMath::float4& posAndNear, const LiteMath::float4& dirAndFar)
{
  PreparedRay r{};
  float tnear = 0.0f, tfar = 0.0f;
  r.valid = litert_detail::RayInterval(posAndNear, dirAndFar, tnear, tfar);

  r.ray.org_x = posAndNear.x;
  r.ray.org_y = posAndNear.y;
  r.ray.org_z = posAndNear.z;
  r.ray.tnear = tnear;
  r.ray.dir_x = dirAndFar.x;
  r.ray.dir_y = dirAndFar.y;
  r.ray.dir_z = dirAndFar.z;
  r.ray.time  = 0.0f;
  r.ray.tfar  = tfar;
  r.ray.mask  = 0xFFFFFFFFu;
  r.ray.id    = 0;
  r.ray.flags = 0;
  return r;
}

class EmbreeRT final : public ISceneObject
{
public:
  EmbreeRT()
  {
    m_device = rtcNewDevice(nullptr);
    if (m_device == nullptr)
      throw std::runtime_error("EmbreeRT: rtcNewDevice failed (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(m_device, embreeErrorCallback, nullptr);
    m_topScene = rtcNewScene(m_device);
  }

  ~EmbreeRT() override
  {
    ClearGeom();
    rtcReleaseScene(m_topScene);
    rtcReleaseDevice(m_device);
  }

  EmbreeRT(const EmbreeRT&)            = delete;
  EmbreeRT& operator=(const EmbreeRT&) = delete;

  const char* Name() const override { return "embree"; }

  void ClearGeom() override
  {
    ClearScene(); // instances would otherwise reference released mesh scenes
    for (Mesh& m : m_meshes)
    {
      if (m.geom != nullptr)
        rtcReleaseGeometry(m.geom);
      rtcReleaseScene(m.scene);
    }
    m_meshes.clear();
  }

  uint32_t AddGeom_Triangles3f(const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum,
                               uint32_t flags, size_t vByteStride) override
  {
    litert_detail::ValidateMesh("EmbreeRT", vpos3f, vertNum, triIndices, indNum, vByteStride);
    Mesh m;
    m.scene = rtcNewScene(m_device);
    m_meshes.push_back(m);
    const uint32_t geomId = uint32_t(m_meshes.size() - 1);
    setMeshData(m_meshes.back(), vpos3f, vertNum, triIndices, indNum, flags, vByteStride);
    return geomId;
  }

  void UpdateGeom_Triangles3f(uint32_t geomId, const float* vpos3f, size_t vertNum, const uint32_t* triIndices,
                              size_t indNum, uint32_t flags, size_t vByteStride) override
  {
    if (geomId >= m_meshes.size())
      throw std::out_of_range("EmbreeRT::UpdateGeom_Triangles3f: invalid geomId " + std::to_string(geomId));
    litert_detail::ValidateMesh("EmbreeRT", vpos3f, vertNum, triIndices, indNum, vByteStride);
    setMeshData(m_meshes[geomId], vpos3f, vertNum, triIndices, indNum, flags, vByteStride);
    m_committed = false; // the top level has to be rebuilt around the changed mesh
  }

  using ISceneObject::AddGeom_AABB;  // and the forms without build flags
  using ISceneObject::UpdateGeom_AABB;
  uint32_t AddGeom_AABB(uint32_t typeId, const CRT_AABB* boxMinMaxF8, size_t boxNumber, uint32_t, void** customPrimPtrs,
                        size_t customPrimCount) override
  {
    Mesh m;
    m.scene = rtcNewScene(m_device);
    m_meshes.push_back(m);
    const uint32_t geomId = uint32_t(m_meshes.size() - 1);
    setBoxData(m_meshes.back(), typeId, boxMinMaxF8, boxNumber, customPrimPtrs, customPrimCount);
    return geomId | CRT_GEOM_MASK_AABB_BIT;
  }

  uint32_t AddGeom_SdfGrid(const litesdf::SdfGrid& grid, uint32_t) override { return addSdf("AddGeom_SdfGrid", grid); }
  uint32_t AddGeom_SdfSVS(const litesdf::SdfSVS& svs, uint32_t) override { return addSdf("AddGeom_SdfSVS", svs); }
  uint32_t AddGeom_SdfSBS(const litesdf::SdfSBS& sbs, uint32_t) override { return addSdf("AddGeom_SdfSBS", sbs); }

  void UpdateGeom_AABB(uint32_t geomId, uint32_t typeId, const CRT_AABB* boxMinMaxF8, size_t boxNumber, uint32_t, void** customPrimPtrs,
                       size_t customPrimCount) override
  {
    geomId &= CRT_GEOM_MASK_AABB_BIT_RM;
    if (geomId >= m_meshes.size() || !m_meshes[geomId].boxes)
      throw std::out_of_range("EmbreeRT::UpdateGeom_AABB: " + std::to_string(geomId) + " is no box geometry");
    setBoxData(m_meshes[geomId], typeId, boxMinMaxF8, boxNumber, customPrimPtrs, customPrimCount);
    m_committed = false;
  }

  uint32_t AddInstanceMotion(uint32_t geomId, const LiteMath::float4x4* matrices, uint32_t matrixNumber) override
  {
    if (matrixNumber == 0)
      throw std::invalid_argument("EmbreeRT::AddInstanceMotion: no matrices");
    for (uint32_t k = 1; k < matrixNumber; k++)
      litert_detail::ValidateInstanceMatrix("EmbreeRT::AddInstanceMotion", matrices[k]);
    const uint32_t instId = AddInstance(geomId, matrices[0]);
    RTCGeometry inst = m_instances[instId];
    rtcSetGeometryTimeStepCount(inst, matrixNumber);  // evenly spaced over [0, 1], interpolated linearly
    for (uint32_t step = 0; step < matrixNumber; step++)
      rtcSetGeometryTransform(inst, step, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &matrices[step].m_col[0].x);
    rtcCommitGeometry(inst);
    return instId;
  }

  void ClearScene() override
  {
    for (RTCGeometry inst : m_instances)
    {
      rtcReleaseGeometry(inst);
    }
    m_instances.clear();
    m_instGeom.clear();
    rtcReleaseScene(m_topScene); // a fresh scene is simpler than detaching every instance
    m_topScene  = rtcNewScene(m_device);
    m_committed = false;
  }

  uint32_t AddInstance(uint32_t geomId, const LiteMath::float4x4& matrix) override
  {
    geomId &= CRT_GEOM_MASK_AABB_BIT_RM;  // box geometry's id may come with its bit
    if (geomId >= m_meshes.size())
      throw std::out_of_range("EmbreeRT::AddInstance: invalid geomId " + std::to_string(geomId));
    litert_detail::ValidateInstanceMatrix("EmbreeRT::AddInstance", matrix);
    const uint32_t instId = uint32_t(m_instances.size());
    RTCGeometry    inst   = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(inst, m_meshes[geomId].scene);
    rtcSetGeometryTimeStepCount(inst, 1);
    setTransform(inst, matrix);
    rtcAttachGeometryByID(m_topScene, inst, instId);
    m_instances.push_back(inst);
    m_instGeom.push_back(geomId);
    m_committed = false;
    return instId;
  }

  void UpdateInstance(uint32_t instanceId, const LiteMath::float4x4& matrix) override
  {
    if (instanceId >= m_instances.size())
      throw std::out_of_range("EmbreeRT::UpdateInstance: invalid instanceId " + std::to_string(instanceId));
    litert_detail::ValidateInstanceMatrix("EmbreeRT::UpdateInstance", matrix);
    setTransform(m_instances[instanceId], matrix);
    m_committed = false;
  }

  void CommitScene(uint32_t options) override
  {
    // Instances of meshes changed since the last commit must be re-committed to pick up new bounds.
    for (size_t i = 0; i < m_instances.size(); i++)
      if (m_meshes[m_instGeom[i]].changed)
        rtcCommitGeometry(m_instances[i]);
    for (Mesh& m : m_meshes)
      m.changed = false;

    rtcSetSceneFlags(m_topScene, (options & BUILD_REFIT) ? RTC_SCENE_FLAG_DYNAMIC : RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(m_topScene, qualityFromFlags(options));
    rtcCommitScene(m_topScene);
    m_committed = true;
  }

  CRT_Hit RayQuery_NearestHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) override
  {
    return RayQuery_NearestHitMotion(posAndNear, dirAndFar, 0.0f);
  }

  bool RayQuery_AnyHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) override
  {
    return RayQuery_AnyHitMotion(posAndNear, dirAndFar, 0.0f);
  }

  CRT_Hit RayQuery_NearestHitMotion(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, float time) override
  {
    CRT_Hit res;
    res.t      = dirAndFar.w;
    res.primId = res.instId = res.geomId = CRT_INVALID_ID;
    res.coords[0] = res.coords[1] = res.coords[2] = res.coords[3] = 0.0f;

    PreparedRay pr = prepareRay(posAndNear, dirAndFar);
    if (!pr.valid || !m_committed)
      return res;

    RTCRayHit rh;
    rh.ray          = pr.ray;
    rh.ray.time     = std::min(std::max(time, 0.0f), 1.0f);
    rh.hit.geomID   = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID   = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;

    RTCIntersectContext ctx; // per call: this is what makes concurrent queries safe
    rtcInitIntersectContext(&ctx);
    rtcIntersect1(m_topScene, &ctx, &rh);

    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || rh.hit.instID[0] == RTC_INVALID_GEOMETRY_ID)
      return res;
    const uint32_t geomId = m_instGeom[rh.hit.instID[0]];
    const Mesh& mesh = m_meshes[geomId];
    res.t         = rh.ray.tfar;
    res.primId    = mesh.boxes ? rh.hit.primID / mesh.boxes->boxesPerPrim : rh.hit.primID;
    res.instId    = rh.hit.instID[0];
    res.geomId    = mesh.boxes ? geomId | CRT_GEOM_MASK_AABB_BIT : geomId;
    res.coords[0] = rh.hit.u;
    res.coords[1] = rh.hit.v;
    if (mesh.sdf)  // the normal (EmbreeSdf.cpp)
    {
      res.coords[0] = rh.hit.Ng_x;
      res.coords[1] = rh.hit.Ng_y;
      res.coords[2] = rh.hit.Ng_z;
    }
    return res;
  }

  bool RayQuery_AnyHitMotion(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar, float time) override
  {
    PreparedRay pr = prepareRay(posAndNear, dirAndFar);
    if (!pr.valid || !m_committed)
      return false;
    pr.ray.time = std::min(std::max(time, 0.0f), 1.0f);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcOccluded1(m_topScene, &ctx, &pr.ray);
    return pr.ray.tfar == -std::numeric_limits<float>::infinity(); // Embree's "occluded" marker
  }

private:
  struct Mesh
  {
    RTCScene    scene   = nullptr; // kept for the mesh's lifetime: instances point at it
    RTCGeometry geom    = nullptr; // null for a mesh without triangles
    size_t      vertNum = 0, triNum = 0;
    bool        changed = false;   // updated since the last CommitScene
    std::shared_ptr<BoxData> boxes; // box geometry: its boxes (Embree keeps a pointer to them)
    std::shared_ptr<void> sdf;      // a signed distance field: what its callbacks read
  };

  template <class Field>
  uint32_t addSdf(const char* what, const Field& field)
  {
    if (const std::string problem = litesdf::Problem(field); !problem.empty())
      throw std::invalid_argument(std::string("EmbreeRT::") + what + ": " + problem);
    Mesh m;
    m.scene = rtcNewScene(m_device);
    m.geom = litert_detail::NewSdfGeometry(m_device, field, m.sdf);
    rtcAttachGeometryByID(m.scene, m.geom, 0);
    rtcCommitScene(m.scene);
    m.changed = true;
    m_meshes.push_back(m);
    return uint32_t(m_meshes.size() - 1);
  }

  void setBoxData(Mesh& m, uint32_t typeId, const CRT_AABB* boxMinMaxF8, size_t boxNumber, void** customPrimPtrs, size_t customPrimCount)
  {
    (void)typeId, (void)customPrimPtrs;
    if (boxNumber > 0 && boxMinMaxF8 == nullptr)
      throw std::invalid_argument("EmbreeRT::AddGeom_AABB: null boxes");
    if (customPrimCount > 0 && boxNumber % customPrimCount != 0)
      throw std::invalid_argument("EmbreeRT::AddGeom_AABB: " + std::to_string(boxNumber) + " boxes are not a multiple of " +
                                  std::to_string(customPrimCount) + " primitives");
    if (m.geom != nullptr)
    {
      rtcDetachGeometry(m.scene, 0);
      rtcReleaseGeometry(m.geom);
      m.geom = nullptr;
    }
    m.boxes = std::make_shared<BoxData>();
    m.boxes->boxes.assign(boxMinMaxF8, boxMinMaxF8 + boxNumber);
    m.boxes->boxesPerPrim = customPrimCount > 0 ? uint32_t(boxNumber / customPrimCount) : 1u;
    if (boxNumber > 0)
    {
      m.geom = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_USER);
      rtcSetGeometryUserPrimitiveCount(m.geom, unsigned(boxNumber));
      rtcSetGeometryUserData(m.geom, m.boxes.get());
      rtcSetGeometryBoundsFunction(m.geom, boxBounds, nullptr);
      rtcSetGeometryIntersectFunction(m.geom, boxIntersect);
      rtcSetGeometryOccludedFunction(m.geom, boxOccluded);
      rtcCommitGeometry(m.geom);
      rtcAttachGeometryByID(m.scene, m.geom, 0);
    }
    m.changed = true;
    rtcCommitScene(m.scene);
  }

  // (Re)fills the mesh's triangle geometry and commits its scene. Buffers are reused in place when
  // the sizes are unchanged (refit-friendly); otherwise the geometry is replaced.
  void setMeshData(Mesh& m, const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum,
                   uint32_t flags, size_t vByteStride)
  {
    const size_t triNum   = indNum / 3;
    const bool   reusable = m.geom != nullptr && !m.boxes && !m.sdf && m.vertNum == vertNum && m.triNum == triNum;
    if (!reusable && m.geom != nullptr)
    {
      rtcDetachGeometry(m.scene, 0);
      rtcReleaseGeometry(m.geom);
      m.geom = nullptr;
    }
    m.boxes.reset();  // triangles now, whatever it was
    m.sdf.reset();

    if (triNum > 0 && vertNum > 0)
    {
      float*    verts = nullptr;
      uint32_t* tris  = nullptr;
      if (reusable)
      {
        verts = static_cast<float*>(rtcGetGeometryBufferData(m.geom, RTC_BUFFER_TYPE_VERTEX, 0));
        tris  = static_cast<uint32_t*>(rtcGetGeometryBufferData(m.geom, RTC_BUFFER_TYPE_INDEX, 0));
      }
      else
      {
        m.geom = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_TRIANGLE);
        // Embree-owned buffers (padded by Embree for its 16-byte vector loads).
        verts = static_cast<float*>(rtcSetNewGeometryBuffer(m.geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                            3 * sizeof(float), vertNum));
        tris  = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(m.geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                               3 * sizeof(uint32_t), triNum));
      }
      if (verts == nullptr || tris == nullptr)
        throw std::runtime_error("EmbreeRT: failed to allocate geometry buffers");

      const char* src = reinterpret_cast<const char*>(vpos3f);
      for (size_t i = 0; i < vertNum; i++)
        std::memcpy(verts + 3 * i, src + i * vByteStride, 3 * sizeof(float));
      std::memcpy(tris, triIndices, indNum * sizeof(uint32_t));

      if (reusable)
      {
        rtcUpdateGeometryBuffer(m.geom, RTC_BUFFER_TYPE_VERTEX, 0);
        rtcUpdateGeometryBuffer(m.geom, RTC_BUFFER_TYPE_INDEX, 0);
      }
      rtcSetGeometryBuildQuality(m.geom, (flags & BUILD_REFIT) ? RTC_BUILD_QUALITY_REFIT : qualityFromFlags(flags));
      rtcCommitGeometry(m.geom);
      if (!reusable)
        rtcAttachGeometryByID(m.scene, m.geom, 0);
    }
    m.vertNum = m.geom ? vertNum : 0;
    m.triNum  = m.geom ? triNum : 0;
    m.changed = true;

    rtcSetSceneFlags(m.scene, (flags & BUILD_REFIT) ? RTC_SCENE_FLAG_DYNAMIC : RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(m.scene, qualityFromFlags(flags));
    rtcCommitScene(m.scene); // instanced scenes must be committed before the top level
  }

  static void setTransform(RTCGeometry inst, const LiteMath::float4x4& matrix)
  {
    // float4x4 stores 4 columns contiguously: exactly Embree's column-major 4x4 layout.
    rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &matrix.m_col[0].x);
    rtcCommitGeometry(inst);
  }

  RTCDevice                m_device   = nullptr;
  RTCScene                 m_topScene = nullptr;
  std::vector<Mesh>        m_meshes;
  std::vector<RTCGeometry> m_instances;
  std::vector<uint32_t>    m_instGeom; // instance id -> geometry id
  bool                     m_committed = false;
};
} // namespace

std::unique_ptr<ISceneObject> CreateEmbreeRT() { return std::make_unique<EmbreeRT>(); }
