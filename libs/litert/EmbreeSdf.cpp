#include "EmbreeSdf.h"

#include "BVHScene.h"  // kSdfNewtonIterations, shared with BVHScene's leaves
#include "SdfLeaves.h"

#include <limits>
#include <variant>

namespace litert_detail {
namespace {

using litesdf::SdfHit;
using LiteMath::float3;

// What the callbacks read: the field, whichever kind it is.
using Field = std::variant<litesdf::SdfGrid, litesdf::SdfSVS, litesdf::SdfSBS>;

unsigned PrimitiveCount(const Field& f)
{
  if (auto* svs = std::get_if<litesdf::SdfSVS>(&f))
    return unsigned(svs->VoxelCount());
  if (auto* sbs = std::get_if<litesdf::SdfSBS>(&f))
    return unsigned(sbs->BrickCount());
  return 1;
}

void Bounds(const RTCBoundsFunctionArguments* args)
{
  const Field& f = *static_cast<const Field*>(args->geometryUserPtr);
  float3 lo, hi;
  if (auto* svs = std::get_if<litesdf::SdfSVS>(&f))
  {
    lo = svs->VoxelMin(args->primID);
    hi = lo + float3(svs->VoxelSize());
  }
  else if (auto* sbs = std::get_if<litesdf::SdfSBS>(&f))
  {
    lo = sbs->BrickMin(args->primID);
    hi = lo + float3(sbs->VoxelSize() * float(sbs->brickSize));
  }
  else
  {
    const auto& grid = std::get<litesdf::SdfGrid>(f);
    lo = grid.boxMin;
    hi = lo + float3(grid.boxSize);
  }
  // Widened a little: Embree's box test may skip a box that a ray with a zero direction component
  // only touches on a face, where the leaf test (exact, on closed boxes) hits. Leaves clip rays to
  // their exact boxes themselves.
  const float3 pad = 1e-6f * (LiteMath::abs(lo) + LiteMath::abs(hi)) + float3(1e-30f);
  lo = lo - pad;
  hi = hi + pad;
  args->bounds_o->lower_x = lo.x;
  args->bounds_o->lower_y = lo.y;
  args->bounds_o->lower_z = lo.z;
  args->bounds_o->upper_x = hi.x;
  args->bounds_o->upper_y = hi.y;
  args->bounds_o->upper_z = hi.z;
}

SdfHit Intersect(const Field& f, unsigned prim, float3 org, float3 dir, float tnear, float tfar)
{
  if (auto* svs = std::get_if<litesdf::SdfSVS>(&f))
    return litesdf::IntersectSVSVoxel(*svs, prim, org, dir, tnear, tfar, kSdfNewtonIterations);
  if (auto* sbs = std::get_if<litesdf::SdfSBS>(&f))
    return litesdf::IntersectSBSBrick(*sbs, prim, org, dir, tnear, tfar, kSdfNewtonIterations);
  return litesdf::IntersectGrid(std::get<litesdf::SdfGrid>(f), org, dir, tnear, tfar, kSdfNewtonIterations);
}

float3 Origin(RTCRayN* ray, unsigned n, unsigned i) { return float3(RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i), RTCRayN_org_z(ray, n, i)); }
float3 Direction(RTCRayN* ray, unsigned n, unsigned i) { return float3(RTCRayN_dir_x(ray, n, i), RTCRayN_dir_y(ray, n, i), RTCRayN_dir_z(ray, n, i)); }

// The normal goes out in Ng (EmbreeRT reports it as the hit's coords[0..2]).
void IntersectN(const RTCIntersectFunctionNArguments* args)
{
  const Field& f = *static_cast<const Field*>(args->geometryUserPtr);
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; i++)
  {
    if (args->valid[i] == 0)
      continue;
    const SdfHit h = Intersect(f, args->primID, Origin(ray, args->N, i), Direction(ray, args->N, i), RTCRayN_tnear(ray, args->N, i),
                               RTCRayN_tfar(ray, args->N, i));
    if (h.t < 0.0f)
      continue;
    RTCRayN_tfar(ray, args->N, i) = h.t;
    RTCHitN_u(hit, args->N, i) = 0.0f;
    RTCHitN_v(hit, args->N, i) = 0.0f;
    RTCHitN_Ng_x(hit, args->N, i) = h.normal.x;
    RTCHitN_Ng_y(hit, args->N, i) = h.normal.y;
    RTCHitN_Ng_z(hit, args->N, i) = h.normal.z;
    RTCHitN_geomID(hit, args->N, i) = args->geomID;
    RTCHitN_primID(hit, args->N, i) = args->primID;
    RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
  }
}

void OccludedN(const RTCOccludedFunctionNArguments* args)
{
  const Field& f = *static_cast<const Field*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; i++)
  {
    if (args->valid[i] == 0)
      continue;
    const SdfHit h = Intersect(f, args->primID, Origin(args->ray, args->N, i), Direction(args->ray, args->N, i),
                               RTCRayN_tnear(args->ray, args->N, i), RTCRayN_tfar(args->ray, args->N, i));
    if (h.t >= 0.0f)
      RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();  // Embree's "occluded"
  }
}

RTCGeometry NewGeometry(RTCDevice device, Field field, std::shared_ptr<void>& keepAlive)
{
  auto data = std::make_shared<Field>(std::move(field));
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geom, PrimitiveCount(*data));
  rtcSetGeometryUserData(geom, data.get());
  rtcSetGeometryBoundsFunction(geom, Bounds, nullptr);
  rtcSetGeometryIntersectFunction(geom, IntersectN);
  rtcSetGeometryOccludedFunction(geom, OccludedN);
  rtcCommitGeometry(geom);
  keepAlive = data;
  return geom;
}

}  // namespace

RTCGeometry NewSdfGeometry(RTCDevice device, const litesdf::SdfGrid& grid, std::shared_ptr<void>& keepAlive)
{
  return NewGeometry(device, grid, keepAlive);
}
RTCGeometry NewSdfGeometry(RTCDevice device, const litesdf::SdfSVS& svs, std::shared_ptr<void>& keepAlive)
{
  return NewGeometry(device, svs, keepAlive);
}
RTCGeometry NewSdfGeometry(RTCDevice device, const litesdf::SdfSBS& sbs, std::shared_ptr<void>& keepAlive)
{
  return NewGeometry(device, sbs, keepAlive);
}

}  // namespace litert_detail
