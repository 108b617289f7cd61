// Embree 3 implementation of ISceneObject.
//
// Layout: one RTCScene per mesh (holding a single triangle geometry with id 0) and a top-level
// RTCScene whose geometries are INSTANCE geometries referencing the mesh scenes. Instance i is
// attached with geometry id i, so Embree's instID is directly our instance id.
#include "CrossRT.h"
#include "SceneInput.h"

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
  switch (flags & 3u)
  {
  case BUILD_LOW: return RTC_BUILD_QUALITY_LOW;
  case BUILD_MEDIUM: return RTC_BUILD_QUALITY_MEDIUM;
  default: return RTC_BUILD_QUALITY_HIGH;
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
    if (geomId >= m_meshes.size())
      throw std::out_of_range("EmbreeRT::AddInstance: invalid geomId " + std::to_string(geomId));
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
    CRT_Hit res;
    res.t      = dirAndFar.w;
    res.primId = res.instId = res.geomId = CRT_INVALID_ID;
    res.coords[0] = res.coords[1] = res.coords[2] = res.coords[3] = 0.0f;

    PreparedRay pr = prepareRay(posAndNear, dirAndFar);
    if (!pr.valid || !m_committed)
      return res;

    RTCRayHit rh;
    rh.ray          = pr.ray;
    rh.hit.geomID   = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID   = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;

    RTCIntersectContext ctx; // per call: this is what makes concurrent queries safe
    rtcInitIntersectContext(&ctx);
    rtcIntersect1(m_topScene, &ctx, &rh);

    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || rh.hit.instID[0] == RTC_INVALID_GEOMETRY_ID)
      return res;
    res.t         = rh.ray.tfar;
    res.primId    = rh.hit.primID;
    res.instId    = rh.hit.instID[0];
    res.geomId    = m_instGeom[rh.hit.instID[0]];
    res.coords[0] = rh.hit.u;
    res.coords[1] = rh.hit.v;
    return res;
  }

  bool RayQuery_AnyHit(LiteMath::float4 posAndNear, LiteMath::float4 dirAndFar) override
  {
    PreparedRay pr = prepareRay(posAndNear, dirAndFar);
    if (!pr.valid || !m_committed)
      return false;
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
  };

  // (Re)fills the mesh's triangle geometry and commits its scene. Buffers are reused in place when
  // the sizes are unchanged (refit-friendly); otherwise the geometry is replaced.
  void setMeshData(Mesh& m, const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum,
                   uint32_t flags, size_t vByteStride)
  {
    const size_t triNum   = indNum / 3;
    const bool   reusable = m.geom != nullptr && m.vertNum == vertNum && m.triNum == triNum;
    if (!reusable && m.geom != nullptr)
    {
      rtcDetachGeometry(m.scene, 0);
      rtcReleaseGeometry(m.geom);
      m.geom = nullptr;
    }

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

std::shared_ptr<ISceneObject> CreateEmbreeRT() { return std::make_shared<EmbreeRT>(); }
