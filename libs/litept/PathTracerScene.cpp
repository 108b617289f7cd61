// PathTracer's scene set-up, on the host: a PathScene's meshes into the ISceneObject, its vertex
// data, materials and textures into the integrator's vectors, a TriangleLight per emissive triangle,
// the environment's sampling distribution, the light choice by power, and the camera.
#include "PathTracer.h"
#include "SceneLoader.h"

#include <cmath>

using namespace LiteMath;
using namespace litept;

void PathTracer::SetScene(const PathScene& scene, std::shared_ptr<ISceneObject> accel)
{
  m_pAccelStruct = std::move(accel);
  m_pAccelStruct->ClearGeom();
  m_positions.clear(), m_normals.clear(), m_tangents.clear(), m_texcoords.clear();
  m_indices.clear(), m_triangleMaterial.clear(), m_geomFirstTriangle.clear();
  std::vector<uint32_t> firstTriangleOfMesh;
  for (const PathScene::Mesh& mesh : scene.meshes)
  {
    const uint32_t geom = m_pAccelStruct->AddGeom_Triangles3f(&mesh.positions[0].x, mesh.positions.size(), mesh.indices.data(), mesh.indices.size(),
                                                              BUILD_HIGH, sizeof(float4));
    const uint32_t firstVertex = uint32_t(m_positions.size());
    const uint32_t firstTriangle = uint32_t(m_triangleMaterial.size());
    if (m_geomFirstTriangle.size() <= geom)
      m_geomFirstTriangle.resize(geom + 1, 0);
    m_geomFirstTriangle[geom] = firstTriangle;
    firstTriangleOfMesh.push_back(firstTriangle);
    m_positions.insert(m_positions.end(), mesh.positions.begin(), mesh.positions.end());
    m_normals.insert(m_normals.end(), mesh.normals.begin(), mesh.normals.end());
    for (size_t i = 0; i < mesh.positions.size(); ++i)
    {
      m_tangents.push_back(i < mesh.tangents.size() ? mesh.tangents[i] : float4(1.0f, 0.0f, 0.0f, 1.0f));
      m_texcoords.push_back(i < mesh.texcoords.size() ? mesh.texcoords[i] : float2(0.0f));
    }
    for (uint32_t index : mesh.indices)
      m_indices.push_back(firstVertex + index);
    m_triangleMaterial.insert(m_triangleMaterial.end(), mesh.triangleMaterial.begin(), mesh.triangleMaterial.end());
  }

  m_materials = scene.materials;
  m_textures = scene.textures;
  if (m_textures.empty())  // the GPU's texture array needs an element
    m_textures.emplace_back(LiteImage::Image2D<float4>(1, 1, float4(1.0f)), LiteImage::Sampler());

  // Per material, the radiance its triangles emit as lights (w: 1 when from both sides), or 0:
  // textured emission is found by BSDF rays only.
  std::vector<float4> lightRadiance;
  for (const auto& material : scene.materials)
  {
    const float3 front = material->Emitted(float3(0.0f, 0.0f, 1.0f), Untextured());
    const float3 back = material->Emitted(float3(0.0f, 0.0f, -1.0f), Untextured());
    const bool emits = front.x + front.y + front.z + back.x + back.y + back.z > 0.0f && material->TextureIds().w < 0;
    lightRadiance.push_back(emits ? to_float4(front.x + front.y + front.z > 0.0f ? front : back, back.x + back.y + back.z > 0.0f ? 1.0f : 0.0f)
                                  : float4(0.0f));
  }

  // Instances, and a light per emissive triangle of each.
  m_lights = scene.lights;
  m_shapeLights.clear();
  for (size_t i = 0; i < m_lights.size(); ++i)
    if (dynamic_cast<const SphereLight*>(m_lights[i].get()) || dynamic_cast<const RectLight*>(m_lights[i].get()))
      m_shapeLights.push_back(uint32_t(i));
  m_shapeLightCount = uint32_t(m_shapeLights.size());
  if (m_shapeLights.empty())
    m_shapeLights.push_back(0u);  // GPU buffers are not empty
  m_instToWorld.clear(), m_instNormalToWorld.clear(), m_instFirstLight.clear(), m_triangleLight.clear();
  m_pAccelStruct->ClearScene();
  for (const PathScene::Instance& inst : scene.instances)
  {
    const PathScene::Mesh& mesh = scene.meshes[inst.mesh];
    const uint32_t id = m_pAccelStruct->AddInstance(inst.mesh, inst.toWorld);
    if (m_instToWorld.size() <= id)
    {
      m_instToWorld.resize(id + 1);
      m_instNormalToWorld.resize(id + 1);
      m_instFirstLight.resize(id + 1, -1);
    }
    m_instToWorld[id] = inst.toWorld;
    m_instNormalToWorld[id] = transpose(inverse4x4(inst.toWorld));
    for (size_t t = 0; t < mesh.triangleMaterial.size(); ++t)
    {
      const float4 radiance = lightRadiance[mesh.triangleMaterial[t]];
      if (radiance.x + radiance.y + radiance.z <= 0.0f)
        continue;
      if (m_instFirstLight[id] < 0)
      {
        m_instFirstLight[id] = int(m_triangleLight.size());
        m_triangleLight.resize(m_triangleLight.size() + mesh.triangleMaterial.size(), -1);
      }
      const float3 p0 = to_float3(inst.toWorld * mesh.positions[mesh.indices[3 * t]]);
      const float3 p1 = to_float3(inst.toWorld * mesh.positions[mesh.indices[3 * t + 1]]);
      const float3 p2 = to_float3(inst.toWorld * mesh.positions[mesh.indices[3 * t + 2]]);
      if (length(cross(p1 - p0, p2 - p0)) <= 0.0f)  // degenerate: nothing to sample
        continue;
      auto light = std::make_shared<TriangleLight>();
      light->v0 = to_float4(p0, 0.0f);
      light->edge1 = to_float4(p1 - p0, 0.0f);
      light->edge2 = to_float4(p2 - p0, 0.0f);
      light->radiance = radiance;
      m_triangleLight[size_t(m_instFirstLight[id]) + t] = int(m_lights.size());
      m_lights.push_back(light);
    }
  }
  if (m_triangleLight.empty())
    m_triangleLight.push_back(-1);  // GPU buffers are not empty
  m_pAccelStruct->CommitScene(BUILD_HIGH);

  float3 boxMin, boxMax;
  SceneBounds(scene, boxMin, boxMax);
  m_sceneRadius = 0.5f * length(boxMax - boxMin);
  for (auto& light : m_lights)
    if (auto* d = dynamic_cast<DirectionalLight*>(light.get()))
      d->sceneRadius = m_sceneRadius;

  // The environment: weights by luminance times the cosine of each row's elevation (the
  // equirectangular map's area element), a marginal CDF over rows and a CDF per row.
  m_envEnabled = 0;
  m_envMap = LiteImage::Image2D<float4>(1, 1, float4(0.0f));
  m_envCdf.assign({0.0f, 1.0f, 0.0f, 1.0f});
  if (scene.environment.width() > 0)
  {
    const uint32_t w = scene.environment.width(), h = scene.environment.height();
    m_envMap = scene.environment;
    m_envSampler.addressU = LiteImage::Sampler::AddressMode::WRAP;
    m_envSampler.addressV = LiteImage::Sampler::AddressMode::CLAMP;
    m_envSampler.filter = LiteImage::Sampler::Filter::LINEAR;
    m_envCdf.assign(size_t(h + 1) + size_t(h) * (w + 1), 0.0f);
    std::vector<double> rowSum(h, 0.0);
    for (uint32_t r = 0; r < h; ++r)
    {
      const float elevation = (0.5f - (float(r) + 0.5f) / float(h)) * kPi;
      const float cosE = std::cos(elevation);
      const size_t first = size_t(h + 1) + size_t(r) * (w + 1);
      double sum = 0.0;
      std::vector<double> running(w + 1, 0.0);
      for (uint32_t c = 0; c < w; ++c)
      {
        sum += double(LiteMath::max(Luminance(to_float3(m_envMap[int2(int(c), int(r))])), 0.0f) * cosE);
        running[c + 1] = sum;
      }
      for (uint32_t c = 0; c <= w; ++c)
        m_envCdf[first + c] = sum > 0.0 ? float(running[c] / sum) : float(c) / float(w);
      m_envCdf[first + w] = 1.0f;
      rowSum[r] = sum;
    }
    double total = 0.0;
    for (uint32_t r = 0; r < h; ++r)
    {
      m_envCdf[r] = float(total);
      total += rowSum[r];
    }
    if (total > 0.0)
    {
      for (uint32_t r = 0; r < h; ++r)
        m_envCdf[r] = float(double(m_envCdf[r]) / total);
      m_envCdf[h] = 1.0f;
      m_envEnabled = 1;
    }
  }

  // Lights are picked by power; the environment, when there are other lights too, half the time.
  std::vector<double> power;
  double lightsPower = 0.0;
  for (const auto& light : m_lights)
  {
    power.push_back(std::max(double(light->Power()), 0.0));
    lightsPower += power.back();
  }
  power.push_back(m_envEnabled != 0 ? (lightsPower > 0.0 ? lightsPower : 1.0) : 0.0);
  double total = 0.0;
  for (double p : power)
    total += p;
  m_lightCdf.assign(power.size() + 1, 0.0f);
  double running = 0.0;
  for (size_t i = 0; i < power.size(); ++i)
  {
    running += power[i];
    m_lightCdf[i + 1] = total > 0.0 ? float(running / total) : 0.0f;
  }
  if (total > 0.0)
    m_lightCdf.back() = 1.0f;

  // The camera.
  const PathScene::Camera& c = scene.camera;
  m_camPos = to_float4(c.position, 1.0f);
  m_camForward = to_float4(normalize(c.forward), 0.0f);
  m_tanHalfFovY = std::tan(0.5f * c.yfov);
  m_lensRadius = c.lensRadius;
  m_focusDistance = c.focusDistance;
  m_upHint = to_float4(c.up, 0.0f);
  SetImageAspect(c.aspect > 0.0f ? c.aspect : 1.0f);
}

void PathTracer::SetImageAspect(float aspect)
{
  const float3 forward = to_float3(m_camForward);
  float3 right = cross(forward, to_float3(m_upHint));
  if (length(right) < 1e-6f)
    right = cross(forward, float3(0.0f, 0.0f, 1.0f));
  right = normalize(right);
  const float3 up = cross(right, forward);
  m_camRight = to_float4(right * (m_tanHalfFovY * aspect), 0.0f);
  m_camUp = to_float4(up * m_tanHalfFovY, 0.0f);
}
