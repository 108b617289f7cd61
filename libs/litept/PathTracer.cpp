// PathTracer's control function and kernels: what the translator reads (PathTracer.h says what each
// does). Scene set-up, which runs on the host only, is in PathTracerScene.cpp.
#include "PathTracer.h"

#include "Gang.h"

#include <cmath>

using namespace LiteMath;
using namespace litept;

namespace {

constexpr uint32_t kMiss = 0xFFFFFFFFu;
constexpr int kRouletteBounce = 3;  // Russian roulette from this bounce on
// A path survives roulette with kRouletteScale times its throughput's largest channel (at most 1),
// so only paths that carry little are cut. Cutting in proportion to the throughput itself (capped at
// 0.95) left the Cornell box with 1.9 times the error at 512 spp for 13% less time. 4 gave the least
// error times time (2 and 8: 18% and 3% more, no roulette 19% more).
constexpr float kRouletteScale = 4.0f;

// Random-number slots of a path vertex (Random4's last argument).
constexpr uint32_t kSlotCamera = 0u;
constexpr uint32_t kSlotLight = 1u;
constexpr uint32_t kSlotBsdf = 2u;

// A point just off the surface on the side `dir` leaves it to, so that the next ray does not hit the
// triangle it starts on.
float3 OffsetRayOrigin(float3 p, float3 geomNormal, float3 dir, float sceneRadius)
{
  const float eps = 1e-4f * (sceneRadius + LiteMath::max(std::fabs(p.x), LiteMath::max(std::fabs(p.y), std::fabs(p.z))));
  return p + geomNormal * (dot(geomNormal, dir) >= 0.0f ? eps : -eps);
}

}  // namespace

void PathTracer::RenderPass(uint32_t width, uint32_t height, uint32_t firstSample, int samples, float4* out_color)
{
  for (uint32_t y = 0; y < height; y++)
    for (uint32_t x = 0; x < width; x++)
    {
      float4 rayPos, rayDir, throughput, pathState, color, shadowPos, shadowDir, shadowColor;
      CRT_Hit hit;
      for (int sample = 0; sample < samples; sample++)
      {
        kernel_InitEyeRay(x, y, width, height, firstSample, sample, &rayPos, &rayDir, &throughput, &pathState);
        for (int bounce = 0; bounce < m_maxDepth + 2; bounce++)
        {
          kernel_RayTrace(x, y, &rayPos, &rayDir, &throughput, &hit);
          kernel_Shade(x, y, width, firstSample, sample, bounce, &hit, &rayPos, &rayDir, &throughput, &pathState, &color, &shadowPos,
                       &shadowDir, &shadowColor);
          kernel_ShadowTrace(x, y, &shadowPos, &shadowDir, &shadowColor, &color);
        }
      }
      kernel_Contribute(x, y, width, &color, out_color);
    }
}

void PathTracer::kernel_InitEyeRay(uint32_t tidX, uint32_t tidY, uint32_t width, uint32_t height, uint32_t firstSample, int sample,
                                   float4* rayPos, float4* rayDir, float4* throughput, float4* pathState)
{
  const uint32_t pixel = (tidY * width + tidX) ^ (m_seed * 0x9E3779B9u);
  const float4 u = Random4(pixel, firstSample + uint32_t(sample), 0u, kSlotCamera);
  // A uniform position in the pixel (a 1-pixel box filter), row 0 at the top.
  const float sx = 2.0f * (float(tidX) + u.x) / float(width) - 1.0f;
  const float sy = 1.0f - 2.0f * (float(tidY) + u.y) / float(height);
  const float3 forward = to_float3(m_camForward);
  const float3 pinholeDir = normalize(forward + to_float3(m_camRight) * sx + to_float3(m_camUp) * sy);
  float3 origin = to_float3(m_camPos);
  float3 dir = pinholeDir;
  if (m_lensRadius > 0.0f)  // a thin lens: rays through a point on the lens meet on the focal plane
  {
    const float r = m_lensRadius * std::sqrt(u.z);
    const float phi = 2.0f * kPi * u.w;
    const float3 lens = normalize(to_float3(m_camRight)) * (r * std::cos(phi)) + normalize(to_float3(m_camUp)) * (r * std::sin(phi));
    const float3 focus = origin + pinholeDir * (m_focusDistance / dot(pinholeDir, forward));
    origin = origin + lens;
    dir = normalize(focus - origin);
  }
  *rayPos = to_float4(origin, 0.0f);
  *rayDir = to_float4(dir, 1e30f);
  *throughput = float4(1.0f, 1.0f, 1.0f, 1.0f);  // w = 1: the path is alive
  *pathState = float4(0.0f);                     // x: the last BSDF sample's density, 0 after a delta lobe or the camera
}

void PathTracer::kernel_RayTrace(uint32_t tidX, uint32_t tidY, const float4* rayPos, const float4* rayDir, const float4* throughput,
                                 CRT_Hit* hit)
{
  (void)tidX;
  (void)tidY;
  const bool alive = throughput->w != 0.0f;
  if (crossrt::GangSize() == 1 && !alive)
  {
    hit->primId = kMiss;
    return;
  }
  // In a SIMD gang (ISPC) a finished path traces an empty interval (tfar = tnear) beside the others
  // rather than leaving: the lanes stay on together, and the traversal runs with its mask known
  // (Gang.h's AllLanesOn). With avx2 on an AMD EPYC (Zen 4) that traced 1.27x the paths a second.
  const float tfar = alive ? rayDir->w : rayPos->w;
  CRT_Hit found = m_pAccelStruct->RayQuery_NearestHit(*rayPos, float4(rayDir->x, rayDir->y, rayDir->z, tfar));
  found.primId = alive ? found.primId : kMiss;
  *hit = found;
}

void PathTracer::kernel_Shade(uint32_t tidX, uint32_t tidY, uint32_t width, uint32_t firstSample, int sample, int bounce,
                              const CRT_Hit* hit, float4* rayPos, float4* rayDir, float4* throughput, float4* pathState, float4* color,
                              float4* shadowPos, float4* shadowDir, float4* shadowColor)
{
  *shadowColor = float4(0.0f);  // w = 0: no shadow ray
  if (throughput->w == 0.0f)
    return;
  const uint32_t pixel = (tidY * width + tidX) ^ (m_seed * 0x9E3779B9u);  // as kernel_InitEyeRay's
  const uint32_t sampleIndex = firstSample + uint32_t(sample);
  const uint32_t vertex = uint32_t(bounce) + 1u;  // 0 is the camera's
  const float3 origin = to_float3(*rayPos);
  const float3 dir = to_float3(*rayDir);
  const float3 beta = to_float3(*throughput);
  const float lastBsdfPdf = pathState->x;

  // Lights with shapes of their own are not in the scene's geometry: a ray that meets one before any
  // surface ends there, with its radiance weighted against the light sample that could have found it.
  float nearest = hit->primId == kMiss ? 1e30f : hit->t;
  int shapeLight = -1;
  for (uint32_t i = 0; i < m_shapeLightCount; i++)
  {
    const uint32_t light = m_shapeLights[i];
    const float t = m_lights[light]->Intersect(origin, dir);
    if (t < nearest)
    {
      nearest = t;
      shapeLight = int(light);
    }
  }
  if (shapeLight >= 0)
  {
    float weight = 1.0f;
    if (lastBsdfPdf > 0.0f)
      weight = PowerHeuristic(lastBsdfPdf, LightChoicePdf(uint32_t(shapeLight)) * m_lights[shapeLight]->Pdf(origin, dir, nearest));
    *color += to_float4(beta * m_lights[shapeLight]->RadianceTowards(dir) * weight, 0.0f);
    throughput->w = 0.0f;
    return;
  }

  if (hit->primId == kMiss)  // the ray left the scene: the environment, weighted against its light sample
  {
    if (m_envEnabled != 0)
    {
      float weight = 1.0f;
      if (lastBsdfPdf > 0.0f)
        weight = PowerHeuristic(lastBsdfPdf, LightChoicePdf(uint32_t(m_lights.size())) * EnvironmentPdf(dir));
      *color += to_float4(beta * Environment(dir) * weight, 0.0f);
    }
    throughput->w = 0.0f;
    return;
  }

  // The surface: position, normals and texture coordinates from the triangle's vertices.
  const uint32_t triangle = m_geomFirstTriangle[hit->geomId] + hit->primId;
  const uint32_t i0 = m_indices[3 * triangle + 0], i1 = m_indices[3 * triangle + 1], i2 = m_indices[3 * triangle + 2];
  const float b1 = hit->coords[0], b2 = hit->coords[1], b0 = 1.0f - b1 - b2;
  const float4x4 toWorld = m_instToWorld[hit->instId];
  const float4x4 normalToWorld = m_instNormalToWorld[hit->instId];
  const float3 p0 = to_float3(toWorld * m_positions[i0]);
  const float3 p1 = to_float3(toWorld * m_positions[i1]);
  const float3 p2 = to_float3(toWorld * m_positions[i2]);
  const float3 position = p0 * b0 + p1 * b1 + p2 * b2;
  float3 geomNormal = normalize(cross(p1 - p0, p2 - p0));
  const float4 objNormal = m_normals[i0] * b0 + m_normals[i1] * b1 + m_normals[i2] * b2;
  const float3 interpolated = to_float3(normalToWorld * float4(objNormal.x, objNormal.y, objNormal.z, 0.0f));
  // Vertex normals that cancel out or are zero (as broken files have them): the face's own.
  float3 normal = dot(interpolated, interpolated) > 1e-20f ? normalize(interpolated) : geomNormal;
  if (dot(normal, geomNormal) < 0.0f)  // the geometric normal follows the shading normal's side
    geomNormal = -1.0f * geomNormal;
  const float2 uv = m_texcoords[i0] * b0 + m_texcoords[i1] * b1 + m_texcoords[i2] * b2;

  const uint32_t materialId = m_triangleMaterial[triangle];
  const int4 textures = m_materials[materialId]->TextureIds();
  const MaterialInputs inputs = MaterialInputsAt(textures, uv);
  if (textures.z >= 0)  // a tangent-space normal map
  {
    const float4 t4 = m_tangents[i0] * b0 + m_tangents[i1] * b1 + m_tangents[i2] * b2;
    float3 tangent = to_float3(toWorld * float4(t4.x, t4.y, t4.z, 0.0f));
    tangent = normalize(tangent - normal * dot(normal, tangent));
    const float3 bitangent = cross(normal, tangent) * (m_tangents[i0].w < 0.0f ? -1.0f : 1.0f);
    const float4 texel = m_textures[textures.z].sample(uv);
    const float3 mapped = float3(2.0f * texel.x - 1.0f, 2.0f * texel.y - 1.0f, 2.0f * texel.z - 1.0f);
    const float3 perturbed = tangent * mapped.x + bitangent * mapped.y + normal * mapped.z;
    if (dot(perturbed, perturbed) > 0.0f)
      normal = normalize(perturbed);
  }
  float3 tangentX, tangentY;
  BranchlessOnb(normal, tangentX, tangentY);
  const float3 wo = ToLocal(-1.0f * dir, tangentX, tangentY, normal);

  // Emission seen along the ray, weighted against the light sample that could have found it.
  const float3 emitted = m_materials[materialId]->Emitted(wo, inputs);
  if (emitted.x + emitted.y + emitted.z > 0.0f)
  {
    float weight = 1.0f;
    const int firstLight = m_instFirstLight[hit->instId];
    if (lastBsdfPdf > 0.0f && firstLight >= 0)
    {
      const int light = m_triangleLight[uint32_t(firstLight) + hit->primId];
      if (light >= 0)
        weight = PowerHeuristic(lastBsdfPdf, LightChoicePdf(uint32_t(light)) * m_lights[light]->Pdf(origin, dir, hit->t));
    }
    *color += to_float4(beta * emitted * weight, 0.0f);
  }
  if (bounce > m_maxDepth)  // one bounce past the last: only the emission its BSDF sample finds
  {
    throughput->w = 0.0f;
    return;
  }

  // Next-event estimation: one light (or the environment), picked by power, and its shadow ray. The
  // point on it takes the group's best-stratified pair of numbers (x, y).
  const float4 ul = Random4(pixel, sampleIndex, vertex, kSlotLight);
  const uint32_t lightCount = uint32_t(m_lights.size());
  if (m_lightCdf[lightCount + 1] > 0.0f)
  {
    uint32_t chosen = 0, end = lightCount + 1u;  // the light with m_lightCdf[chosen] <= ul.z < m_lightCdf[chosen + 1]
    while (end - chosen > 1u)
    {
      const uint32_t mid = (chosen + end) / 2u;
      if (m_lightCdf[mid] <= ul.z)
        chosen = mid;
      else
        end = mid;
    }
    LightSample ls;
    if (chosen < lightCount)
      ls = m_lights[chosen]->Sample(position, float2(ul.x, ul.y));
    else
      ls = SampleEnvironment(float2(ul.x, ul.y));
    const float choicePdf = LightChoicePdf(chosen);
    const float lightPdf = ls.radiancePdf.w * choicePdf;
    if (lightPdf > 0.0f)
    {
      const float3 toLight = to_float3(ls.dirDist);
      const float3 wiLight = ToLocal(toLight, tangentX, tangentY, normal);
      const float4 f = m_materials[materialId]->Evaluate(wo, wiLight, inputs);
      // The geometry must agree with the shading frame on whether the light is reflected or transmitted.
      const bool reflects = wiLight.z * wo.z > 0.0f;
      const bool geomReflects = dot(toLight, geomNormal) * dot(-1.0f * dir, geomNormal) > 0.0f;
      if (f.x + f.y + f.z > 0.0f && reflects == geomReflects)
      {
        const float weight = ls.delta != 0u ? 1.0f : PowerHeuristic(lightPdf, f.w);
        const float3 contribution = beta * to_float3(f) * to_float3(ls.radiancePdf) * (weight / lightPdf);
        const float3 start = OffsetRayOrigin(position, geomNormal, toLight, m_sceneRadius);
        // The ray aims from where it starts at the light's point and stops just short of it. Kept
        // parallel to toLight, a ray lifted off the surface would meet the light's plane before the
        // point when the light is seen obliquely, and hit the light itself (a glossy reflection of
        // the light lost a third of its energy so).
        float3 shadowDirection = toLight;
        float far = 1e30f;
        if (ls.dirDist.w < 1e30f)
        {
          const float3 toPoint = position + toLight * ls.dirDist.w - start;
          const float distance = length(toPoint);
          shadowDirection = toPoint * (1.0f / distance);
          far = distance * (1.0f - 1e-4f);
        }
        // Lights with shapes are not in the scene's geometry that the shadow ray is traced through:
        // one in the way (not the light sampled) blocks it here, as it would any other ray.
        bool blocked = false;
        for (uint32_t i = 0; i < m_shapeLightCount; i++)
          if (m_shapeLights[i] != chosen && m_lights[m_shapeLights[i]]->Intersect(start, shadowDirection) < far)
            blocked = true;
        if (!blocked)
        {
          *shadowPos = to_float4(start, 0.0f);
          *shadowDir = to_float4(shadowDirection, far);
          *shadowColor = to_float4(contribution, 1.0f);
        }
      }
    }
  }

  // The next ray, drawn from the BSDF.
  const BsdfSample bs = m_materials[materialId]->Sample(wo, Random4(pixel, sampleIndex, vertex, kSlotBsdf), inputs);
  const float3 wi = ToWorld(to_float3(bs.wiPdf), tangentX, tangentY, normal);
  // A direction the shading normal allows but the geometry does not (it would leak through the
  // surface) ends the path.
  const bool transmitted = (bs.flags & kBsdfTransmission) != 0u;
  const bool below = dot(wi, geomNormal) * dot(-1.0f * dir, geomNormal) < 0.0f;
  if (bs.weight.w == 0.0f || below != transmitted)
  {
    throughput->w = 0.0f;
    return;
  }
  float3 nextBeta = beta * to_float3(bs.weight);
  if (bounce >= kRouletteBounce)
  {
    const float survive = LiteMath::min(kRouletteScale * LiteMath::max(nextBeta.x, LiteMath::max(nextBeta.y, nextBeta.z)), 1.0f);
    if (ul.w >= survive)
    {
      throughput->w = 0.0f;
      return;
    }
    nextBeta = nextBeta * (1.0f / survive);
  }
  *throughput = to_float4(nextBeta, 1.0f);
  *pathState = float4((bs.flags & kBsdfDelta) != 0u ? 0.0f : bs.wiPdf.w, 0.0f, 0.0f, 0.0f);
  *rayPos = to_float4(OffsetRayOrigin(position, geomNormal, wi, m_sceneRadius), 0.0f);
  *rayDir = to_float4(wi, 1e30f);
}

void PathTracer::kernel_ShadowTrace(uint32_t tidX, uint32_t tidY, const float4* shadowPos, const float4* shadowDir,
                                    const float4* shadowColor, float4* color)
{
  (void)tidX;
  (void)tidY;
  const bool alive = shadowColor->w != 0.0f;
  if (crossrt::GangSize() == 1 && !alive)
    return;
  // In a gang, no shadow ray is an empty interval beside the others (as in kernel_RayTrace).
  const float tfar = alive ? shadowDir->w : shadowPos->w;
  const bool blocked = m_pAccelStruct->RayQuery_AnyHit(*shadowPos, float4(shadowDir->x, shadowDir->y, shadowDir->z, tfar));
  if (alive && !blocked)
    *color += float4(shadowColor->x, shadowColor->y, shadowColor->z, 0.0f);
}

void PathTracer::kernel_Contribute(uint32_t tidX, uint32_t tidY, uint32_t width, const float4* color, float4* out_color)
{
  out_color[tidY * width + tidX] = float4(color->x, color->y, color->z, 1.0f);
}

// ---------------------------------------------------------------- helpers

MaterialInputs PathTracer::MaterialInputsAt(int4 textures, float2 uv) const
{
  MaterialInputs in = Untextured();
  if (textures.x >= 0)
    in.baseColor = m_textures[textures.x].sample(uv);
  if (textures.y >= 0)
    in.metallicRoughness = m_textures[textures.y].sample(uv);
  if (textures.w >= 0)
    in.emissive = m_textures[textures.w].sample(uv);
  return in;
}

// The map's orientation is Cycles' after Blender's glTF importer turns Y-up into Z-up (measured
// with scripts/cycles-reference.py): for a glTF direction d, u = 1/2 + atan2(d.z, d.x) / 2 pi, and
// the elevation asin(d.y) runs from the bottom row (-pi/2) to the top one (pi/2).
float3 PathTracer::Environment(float3 dir) const
{
  const float u = std::atan2(dir.z, dir.x) * (0.5f * kInvPi) + 0.5f;
  const float v = 0.5f - std::atan2(dir.y, std::sqrt(dir.x * dir.x + dir.z * dir.z)) * kInvPi;
  return to_float3(m_envMap.sample(m_envSampler, float2(u, v)));
}

uint32_t PathTracer::SampleCdf(uint32_t first, uint32_t count, float u) const
{
  uint32_t lo = 0, hi = count;  // the answer is in [lo, hi)
  while (hi - lo > 1u)
  {
    const uint32_t mid = (lo + hi) / 2u;
    if (m_envCdf[first + mid] <= u)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

float PathTracer::EnvironmentPdf(float3 dir) const
{
  const uint32_t w = m_envMap.width(), h = m_envMap.height();
  const float u = std::atan2(dir.z, dir.x) * (0.5f * kInvPi) + 0.5f;
  const float elevation = std::atan2(dir.y, std::sqrt(dir.x * dir.x + dir.z * dir.z));
  const float v = 0.5f - elevation * kInvPi;
  const uint32_t col = uint32_t(LiteMath::clamp(int(u * float(w)), 0, int(w) - 1));
  const uint32_t row = uint32_t(LiteMath::clamp(int(v * float(h)), 0, int(h) - 1));
  const float rowPdf = m_envCdf[row + 1] - m_envCdf[row];
  const uint32_t cols = (h + 1u) + row * (w + 1u);
  const float colPdf = m_envCdf[cols + col + 1] - m_envCdf[cols + col];
  const float cosElevation = std::cos(elevation);
  if (cosElevation <= 0.0f)
    return 0.0f;
  return rowPdf * colPdf * float(w) * float(h) / (2.0f * kPi * kPi * cosElevation);
}

LightSample PathTracer::SampleEnvironment(float2 u) const
{
  const uint32_t w = m_envMap.width(), h = m_envMap.height();
  // A row by the marginal distribution, a column within it, then uniformly inside the texel (the
  // first number is reused, rescaled, for the position in the texel).
  const uint32_t row = SampleCdf(0u, h, u.y);
  const float rowPdf = m_envCdf[row + 1] - m_envCdf[row];
  const float vIn = rowPdf > 0.0f ? (u.y - m_envCdf[row]) / rowPdf : 0.5f;
  const uint32_t cols = (h + 1u) + row * (w + 1u);
  const uint32_t col = SampleCdf(cols, w, u.x);
  const float colPdf = m_envCdf[cols + col + 1] - m_envCdf[cols + col];
  const float uIn = colPdf > 0.0f ? (u.x - m_envCdf[cols + col]) / colPdf : 0.5f;
  const float mu = (float(col) + LiteMath::clamp(uIn, 0.0f, 0.9999f)) / float(w);
  const float mv = (float(row) + LiteMath::clamp(vIn, 0.0f, 0.9999f)) / float(h);
  const float elevation = (0.5f - mv) * kPi;
  const float phi = (mu - 0.5f) * 2.0f * kPi;
  const float c = std::cos(elevation);
  const float3 dir = float3(c * std::cos(phi), std::sin(elevation), c * std::sin(phi));
  LightSample s;
  s.dirDist = to_float4(dir, 1e30f);
  s.delta = 0u;
  if (c <= 0.0f || rowPdf * colPdf <= 0.0f)
  {
    s.radiancePdf = float4(0.0f);
    return s;
  }
  const float pdf = rowPdf * colPdf * float(w) * float(h) / (2.0f * kPi * kPi * c);
  s.radiancePdf = to_float4(to_float3(m_envMap.sample(m_envSampler, float2(mu, mv))), pdf);
  return s;
}

float PathTracer::LightChoicePdf(uint32_t light) const { return m_lightCdf[light + 1] - m_lightCdf[light]; }
