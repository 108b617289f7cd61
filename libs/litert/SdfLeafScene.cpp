#include "SdfLeafScene.h"
#include "SceneInput.h"
#include <algorithm>
#include <cmath>
#include <stdexcept>

using LiteMath::float3;
using LiteMath::float4;
using LiteMath::float4x4;

namespace
{
constexpr int kNewtonIterations = 4;
constexpr uint32_t kNoId = 0xFFFFFFFFu;
constexpr int kStackSize = 64;  // the tree halves its leaves per level: 2^63 leaves before it overflows

float3 Xyz(float4 v) { return float3(v.x, v.y, v.z); }

// The ray's span in the box [lo, hi] within [near, far]: false when it misses. A ray in a face's
// plane (0 * inf) keeps the other axes' span (litesdf::RayBox).
bool Span(float3 org, float3 dir, float3 lo, float3 hi, float near, float far, float& t0, float& t1)
{
  return litesdf::RayBox(org, float3(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z), lo, hi, near, far, t0, t1);
}

// The ray in the field's space (t is the same there: the direction is not normalised again).
void ToField(const SdfPlacement& place, float4 posAndNear, float4 dirAndFar, float3& org, float3& dir)
{
  const float4 o = float4(posAndNear.x, posAndNear.y, posAndNear.z, 1.0f), d = float4(dirAndFar.x, dirAndFar.y, dirAndFar.z, 0.0f);
  org = float3(LiteMath::dot(place.toObject0, o), LiteMath::dot(place.toObject1, o), LiteMath::dot(place.toObject2, o));
  dir = float3(LiteMath::dot(place.toObject0, d), LiteMath::dot(place.toObject1, d), LiteMath::dot(place.toObject2, d));
}

// Records h as the hit when it is nearer than the hit so far.
void Record(const litesdf::SdfHit& h, const CRT_LeafInfo& info, const SdfPlacement& place, CRT_Hit& hit)
{
  if (h.t >= 0.0f && h.t < hit.t)
  {
    hit.t = h.t;
    hit.primId = info.aabbId;
    hit.instId = place.instId;
    hit.geomId = place.geomId;
    hit.coords[0] = h.normal.x;
    hit.coords[1] = h.normal.y;
    hit.coords[2] = h.normal.z;
  }
}

bool Finite(float4 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// A copy of a field's leaves with a placement (host only).
template <class Leaves>
std::shared_ptr<ISdfLeaves> Placed(const std::shared_ptr<ISdfLeaves>& field, const SdfPlacement& place)
{
  auto leaves = std::make_shared<Leaves>(*std::static_pointer_cast<Leaves>(field));
  leaves->place = place;
  return leaves;
}
// The box of a cube with corner lo and edge `edge`.
CRT_AABB CubeBox(float3 lo, float edge) { return {float4(lo.x, lo.y, lo.z, 0.0f), float4(lo.x + edge, lo.y + edge, lo.z + edge, 0.0f)}; }

}  // namespace

// ---- The leaves' intersections, one class per representation ----

void SdfGridLeaves::Intersect(float4 posAndNear, float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit, const SdfLeafScene* scene) const
{
  float3 org, dir;
  ToField(place, posAndNear, dirAndFar, org, dir);
  const uint32_t brick = scene->m_gridBricks[firstBrick + info.aabbId];
  const uint32_t bx = brick % bricksPerAxis, by = (brick / bricksPerAxis) % bricksPerAxis, bz = brick / (bricksPerAxis * bricksPerAxis);
  const float cell = boxMinAndCell.w, edge = cell * float(brickCells);
  const float3 corner = Xyz(boxMinAndCell) + edge * float3(float(bx), float(by), float(bz));
  float t0, t1;
  if (!Span(org, dir, corner, corner + float3(edge, edge, edge), posAndNear.w, hit.t, t0, t1))
    return;
  const uint32_t first = firstValue + ((bz * samples + by) * samples + bx) * brickCells;
  Record(scene->MarchBrick(corner, cell, int(brickCells), first, samples, samples * samples, org, dir, t0, t1), info, place, hit);
}

void SdfSVSLeaves::Intersect(float4 posAndNear, float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit, const SdfLeafScene* scene) const
{
  float3 org, dir;
  ToField(place, posAndNear, dirAndFar, org, dir);
  const uint32_t voxel = firstVoxel + info.aabbId;
  const float4 box = scene->m_voxels[voxel];
  float t0, t1;
  if (!Span(org, dir, Xyz(box), Xyz(box) + float3(box.w, box.w, box.w), posAndNear.w, hit.t, t0, t1))
    return;
  litesdf::VoxelValues values;
  for (uint32_t c = 0; c < 8; ++c)
    values.v[c] = scene->m_voxelValues[8 * voxel + c];
  Record(litesdf::IntersectVoxelSpan(values, Xyz(box), box.w, org, dir, t0, t1, kNewtonIterations), info, place, hit);
}

void SdfSBSLeaves::Intersect(float4 posAndNear, float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit, const SdfLeafScene* scene) const
{
  float3 org, dir;
  ToField(place, posAndNear, dirAndFar, org, dir);
  const uint32_t brick = firstBrick + info.aabbId;
  const float4 box = scene->m_bricks[brick];
  const float edge = box.w * float(brickSize);
  float t0, t1;
  if (!Span(org, dir, Xyz(box), Xyz(box) + float3(edge, edge, edge), posAndNear.w, hit.t, t0, t1))
    return;
  const uint32_t side = brickSize + 1;
  Record(scene->MarchBrick(Xyz(box), box.w, int(brickSize), scene->m_brickValues[brick], side, side * side, org, dir, t0, t1), info, place, hit);
}

litesdf::SdfHit SdfLeafScene::MarchBrick(float3 corner, float cell, int n, uint32_t first, uint32_t strideY, uint32_t strideZ, float3 org, float3 dir,
                                         float t0, float t1) const
{
  litesdf::SdfHit hit = MarchBrickOnce(corner, cell, n, first, strideY, strideZ, org, dir, t0, t1);
  // Profiling only (m_intersectRepeats, in the header): the same brick again, its answer kept where
  // it is nearer, which with m_repeatSlack = 0 it never is.
  for (uint32_t r = 1; r < m_intersectRepeats; ++r)
  {
    const litesdf::SdfHit again = MarchBrickOnce(corner, cell, n, first, strideY, strideZ, org, dir, t0, t1 + m_repeatSlack);
    if (again.t >= 0.0f && (hit.t < 0.0f || again.t < hit.t))
      hit = again;
  }
  return hit;
}

litesdf::SdfHit SdfLeafScene::MarchBrickOnce(float3 corner, float cell, int n, uint32_t first, uint32_t strideY, uint32_t strideZ, float3 org,
                                             float3 dir, float t0, float t1) const
{
  // The cells in order along the ray (Amanatides and Woo), each solved until one is hit; a cell with
  // no corner at or inside the surface cannot hold it (litesdf's MayHoldSurface) and is not solved.
  // (litesdf's MarchVoxels walks the same way, but takes a callable, which kernels cannot pass.)
  const float3 entry = (org + t0 * dir - corner) / cell;
  int at[3];
  int step[3];
  float tNext[3];
  float tDelta[3];
  for (int a = 0; a < 3; ++a)
  {
    at[a] = LiteMath::clamp(int(std::floor(entry[a])), 0, n - 1);
    step[a] = dir[a] > 0.0f ? 1 : -1;
    const float boundary = corner[a] + cell * float(at[a] + (dir[a] > 0.0f ? 1 : 0));
    tNext[a] = dir[a] != 0.0f ? (boundary - org[a]) / dir[a] : 1e30f;
    tDelta[a] = dir[a] != 0.0f ? cell / std::fabs(dir[a]) : 1e30f;
  }
  float tEnter = t0;
  while (true)
  {
    const int a = tNext[0] < tNext[1] ? (tNext[0] < tNext[2] ? 0 : 2) : (tNext[1] < tNext[2] ? 1 : 2);
    const uint32_t base = first + uint32_t(at[0]) + uint32_t(at[1]) * strideY + uint32_t(at[2]) * strideZ;
    litesdf::VoxelValues values;
    for (uint32_t c = 0; c < 8; ++c)
      values.v[c] = m_values[base + (c & 1u) + ((c >> 1u) & 1u) * strideY + (c >> 2u) * strideZ];
    const float3 cellMin = corner + cell * float3(float(at[0]), float(at[1]), float(at[2]));
    const litesdf::SdfHit h = litesdf::MayHoldSurface(values)
                                  ? litesdf::IntersectVoxelSpan(values, cellMin, cell, org, dir, tEnter, std::min(tNext[a], t1), kNewtonIterations)
                                  : litesdf::Missed();
    if (h.t >= 0.0f)
      return h;
    if (!(tNext[a] <= t1))
      return h;  // left the brick (h is the miss)
    at[a] = at[a] + step[a];
    if (at[a] < 0 || at[a] >= n)
      return h;
    tEnter = tNext[a];
    tNext[a] = tNext[a] + tDelta[a];
  }
}

// ---- The traversal (paper 3.10, listing 2) ----

// The tree's nodes the ray meets, nearer than the nearest hit so far; at each leaf, its field's
// intersection function. Rays with NaN or inf components, a zero direction or tmin >= tmax miss.
CRT_Hit SdfLeafScene::RayQuery_NearestHit(float4 posAndNear, float4 dirAndFar)
{
  CRT_Hit hit;
  hit.t = dirAndFar.w;
  hit.primId = kNoId;
  hit.instId = kNoId;
  hit.geomId = kNoId;
  for (int i = 0; i < 4; ++i)
    hit.coords[i] = 0.0f;
  const float3 org = Xyz(posAndNear), dir = Xyz(dirAndFar);
  const bool valid = Finite(posAndNear) && Finite(dirAndFar) && LiteMath::dot(dir, dir) > 0.0f && posAndNear.w < dirAndFar.w;
  uint32_t stack[kStackSize];
  int top = 0;
  if (valid && !m_nodeMin.empty())
    stack[top++] = 0;
  while (top > 0)
  {
    const uint32_t node = stack[--top];
    float t0, t1;
    if (!Span(org, dir, Xyz(m_nodeMin[node]), Xyz(m_nodeMax[node]), posAndNear.w, hit.t, t0, t1))
      continue;
    if (m_nodeLeaf[node] == 0)
    {
      stack[top++] = m_nodeRight[node];
      stack[top++] = node + 1;
      continue;
    }
    CRT_LeafInfo info;
    info.aabbId = m_leafIds[m_nodeLeaf[node] - 1].y;
    info.primId = info.aabbId;
    info.instId = m_leafIds[m_nodeLeaf[node] - 1].x;
    info.geomId = m_leafIds[m_nodeLeaf[node] - 1].x;
    info.rayxId = 0;
    info.rayyId = 0;
    m_geom[info.geomId]->Intersect(posAndNear, dirAndFar, info, hit, this);
  }
  return hit;
}

bool SdfLeafScene::RayQuery_AnyHit(float4 posAndNear, float4 dirAndFar) { return RayQuery_NearestHit(posAndNear, dirAndFar).primId != kNoId; }

// ---- Host only: fields, instances, their boxes, the tree ----

void SdfLeafScene::ClearGeom()
{
  m_fields.clear();
  m_values.clear();
  m_gridBricks.clear();
  m_voxelValues.clear();
  m_voxels.clear();
  m_bricks.clear();
  m_brickValues.clear();
  ClearScene();
}

uint32_t SdfLeafScene::AddGeom_Triangles3f(const float*, size_t, const uint32_t*, size_t, uint32_t, size_t)
{
  throw std::runtime_error("SdfLeafScene holds signed distance fields only: trace triangle meshes with BVHScene");
}

void SdfLeafScene::UpdateGeom_Triangles3f(uint32_t, const float*, size_t, const uint32_t*, size_t, uint32_t, size_t)
{
  throw std::runtime_error("SdfLeafScene holds signed distance fields only: trace triangle meshes with BVHScene");
}

uint32_t SdfLeafScene::AddGeom_SdfGrid(const litesdf::SdfGrid& grid, uint32_t)
{
  if (const std::string problem = litesdf::Problem(grid); !problem.empty())
    throw std::invalid_argument("SdfLeafScene::AddGeom_SdfGrid: " + problem);
  if ((grid.samples - 1) % m_gridBrickCells != 0)
    throw std::invalid_argument("SdfLeafScene::AddGeom_SdfGrid: the grid's " + std::to_string(grid.samples - 1) + " cells per axis are not a multiple of " +
                                std::to_string(m_gridBrickCells) + ", the leaves' (SdfLeafScene's gridBrickCells)");
  auto leaves = std::make_shared<SdfGridLeaves>();
  leaves->boxMinAndCell = float4(grid.boxMin.x, grid.boxMin.y, grid.boxMin.z, grid.CellSize());
  leaves->firstValue = uint32_t(m_values.size());
  leaves->samples = grid.samples;
  leaves->brickCells = m_gridBrickCells;
  leaves->bricksPerAxis = (grid.samples - 1) / m_gridBrickCells;
  leaves->firstBrick = uint32_t(m_gridBricks.size());
  m_values.insert(m_values.end(), grid.values.begin(), grid.values.end());
  Field field{0, leaves, {}};
  const uint32_t n = leaves->bricksPerAxis, b = m_gridBrickCells;
  const float edge = grid.CellSize() * float(b);
  for (uint32_t i = 0; i < n * n * n; ++i)
  {
    // A leaf where the surface may cross the brick: its samples are not all of one sign.
    const uint32_t x0 = i % n * b, y0 = i / n % n * b, z0 = i / (n * n) * b;
    float lowest = INFINITY, highest = -INFINITY;
    for (uint32_t z = z0; z <= z0 + b; ++z)
      for (uint32_t y = y0; y <= y0 + b; ++y)
        for (uint32_t x = x0; x <= x0 + b; ++x)
        {
          lowest = std::min(lowest, grid.Value(x, y, z));
          highest = std::max(highest, grid.Value(x, y, z));
        }
    if (!(lowest <= 0.0f && highest >= 0.0f))
      continue;
    m_gridBricks.push_back(i);
    const float3 lo = grid.boxMin + edge * float3(float(i % n), float(i / n % n), float(i / (n * n)));
    field.leafBoxes.push_back(CubeBox(lo, edge));
  }
  m_fields.push_back(field);
  return uint32_t(m_fields.size() - 1);
}

uint32_t SdfLeafScene::AddGeom_SdfSVS(const litesdf::SdfSVS& svs, uint32_t)
{
  if (const std::string problem = litesdf::Problem(svs); !problem.empty())
    throw std::invalid_argument("SdfLeafScene::AddGeom_SdfSVS: " + problem);
  auto leaves = std::make_shared<SdfSVSLeaves>();
  leaves->firstVoxel = uint32_t(m_voxels.size());
  leaves->voxelCount = uint32_t(svs.VoxelCount());
  Field field{1, leaves, {}};
  const float edge = svs.VoxelSize();
  for (size_t i = 0; i < svs.VoxelCount(); ++i)
  {
    const float3 lo = svs.VoxelMin(i);
    m_voxels.push_back(float4(lo.x, lo.y, lo.z, edge));
    const litesdf::VoxelValues v = svs.Values(i);
    m_voxelValues.insert(m_voxelValues.end(), v.v, v.v + 8);
    field.leafBoxes.push_back(CubeBox(lo, edge));
  }
  m_fields.push_back(field);
  return uint32_t(m_fields.size() - 1);
}

uint32_t SdfLeafScene::AddGeom_SdfSBS(const litesdf::SdfSBS& sbs, uint32_t)
{
  if (const std::string problem = litesdf::Problem(sbs); !problem.empty())
    throw std::invalid_argument("SdfLeafScene::AddGeom_SdfSBS: " + problem);
  auto leaves = std::make_shared<SdfSBSLeaves>();
  leaves->firstBrick = uint32_t(m_bricks.size());
  leaves->brickCount = uint32_t(sbs.BrickCount());
  leaves->brickSize = sbs.brickSize;
  Field field{2, leaves, {}};
  const uint32_t b = sbs.brickSize;
  const float edge = sbs.VoxelSize() * float(b);
  for (size_t brick = 0; brick < sbs.BrickCount(); ++brick)
  {
    const float3 lo = sbs.BrickMin(brick);
    m_bricks.push_back(float4(lo.x, lo.y, lo.z, sbs.VoxelSize()));
    m_brickValues.push_back(uint32_t(m_values.size()));
    // Value (x, y, z), 0 <= x, y, z <= b: a corner of voxel (min(x, b - 1), ...).
    for (uint32_t z = 0; z <= b; ++z)
      for (uint32_t y = 0; y <= b; ++y)
        for (uint32_t x = 0; x <= b; ++x)
        {
          const litesdf::VoxelValues v = sbs.Values(brick, std::min(x, b - 1), std::min(y, b - 1), std::min(z, b - 1));
          m_values.push_back(v.v[(x == b ? 1 : 0) + (y == b ? 2 : 0) + (z == b ? 4 : 0)]);
        }
    field.leafBoxes.push_back(CubeBox(lo, edge));
  }
  m_fields.push_back(field);
  return uint32_t(m_fields.size() - 1);
}

void SdfLeafScene::ClearScene()
{
  m_instances.clear();
  m_geom.clear();
  m_nodeMin.clear();
  m_nodeMax.clear();
  m_nodeRight.clear();
  m_nodeLeaf.clear();
  m_leafIds.clear();
}

uint32_t SdfLeafScene::AddInstance(uint32_t geomId, const float4x4& matrix)
{
  if (geomId >= m_fields.size())
    throw std::invalid_argument("SdfLeafScene::AddInstance: no field " + std::to_string(geomId) + " (" + std::to_string(m_fields.size()) + " added)");
  litert_detail::ValidateInstanceMatrix("SdfLeafScene::AddInstance", matrix);
  m_instances.push_back({geomId, matrix});
  return uint32_t(m_instances.size() - 1);
}

void SdfLeafScene::UpdateInstance(uint32_t instanceId, const float4x4& matrix)
{
  litert_detail::ValidateInstanceMatrix("SdfLeafScene::UpdateInstance", matrix);
  m_instances.at(instanceId).second = matrix;
}

// Per instance, its field's leaves with a placement (m_geom), and the tree over every instance's
// world-space leaf boxes.
void SdfLeafScene::CommitScene(uint32_t)
{
  m_geom.clear();
  std::vector<Leaf> leaves;
  for (uint32_t k = 0; k < m_instances.size(); ++k)
  {
    const auto& [geomId, toWorld] = m_instances[k];
    const Field& field = m_fields[geomId];
    SdfPlacement place;
    const float4x4 toObject = LiteMath::inverse4x4(toWorld);
    place.toObject0 = toObject.get_row(0);
    place.toObject1 = toObject.get_row(1);
    place.toObject2 = toObject.get_row(2);
    place.geomId = geomId;
    place.instId = k;
    m_geom.push_back(field.kind == 0   ? Placed<SdfGridLeaves>(field.prototype, place)
                     : field.kind == 1 ? Placed<SdfSVSLeaves>(field.prototype, place)
                                       : Placed<SdfSBSLeaves>(field.prototype, place));
    const std::vector<CRT_AABB> boxes = LeafBoxes(k);
    for (uint32_t i = 0; i < boxes.size(); ++i)
      leaves.push_back({boxes[i], k, i});
  }
  m_nodeMin.clear();
  m_nodeMax.clear();
  m_nodeRight.clear();
  m_nodeLeaf.clear();
  m_leafIds.clear();
  if (!leaves.empty())
    Build(leaves, 0, leaves.size());
}

std::vector<CRT_AABB> SdfLeafScene::LeafBoxes(uint32_t geomId) const
{
  const auto& [field, toWorld] = m_instances.at(geomId);
  std::vector<CRT_AABB> boxes;
  for (const CRT_AABB& box : m_fields[field].leafBoxes)
  {
    // The world box around the field box's eight corners.
    float4 lo = float4(INFINITY, INFINITY, INFINITY, 0.0f), hi = float4(-INFINITY, -INFINITY, -INFINITY, 0.0f);
    for (int c = 0; c < 8; ++c)
    {
      const float4 p = toWorld * float4(c & 1 ? box.boxMax.x : box.boxMin.x, c & 2 ? box.boxMax.y : box.boxMin.y, c & 4 ? box.boxMax.z : box.boxMin.z, 1.0f);
      lo = LiteMath::min(lo, float4(p.x, p.y, p.z, 0.0f));
      hi = LiteMath::max(hi, float4(p.x, p.y, p.z, 0.0f));
    }
    boxes.push_back({lo, hi});
  }
  return boxes;
}

// A node over leaves [begin, end), split at the median along its box's longest axis.
uint32_t SdfLeafScene::Build(std::vector<Leaf>& leaves, size_t begin, size_t end)
{
  float4 lo = leaves[begin].box.boxMin, hi = leaves[begin].box.boxMax;
  for (size_t i = begin + 1; i < end; ++i)
  {
    lo = LiteMath::min(lo, leaves[i].box.boxMin);
    hi = LiteMath::max(hi, leaves[i].box.boxMax);
  }
  const uint32_t node = uint32_t(m_nodeMin.size());
  m_nodeMin.push_back(lo);
  m_nodeMax.push_back(hi);
  m_nodeRight.push_back(0);
  m_nodeLeaf.push_back(0);
  if (end - begin == 1)
  {
    m_leafIds.push_back(LiteMath::uint2(leaves[begin].element, leaves[begin].aabbId));
    m_nodeLeaf[node] = uint32_t(m_leafIds.size());
    return node;
  }
  const float4 extent = hi - lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  const size_t middle = (begin + end) / 2;
  std::nth_element(leaves.begin() + long(begin), leaves.begin() + long(middle), leaves.begin() + long(end),
                   [axis](const Leaf& a, const Leaf& b) { return a.box.boxMin[axis] + a.box.boxMax[axis] < b.box.boxMin[axis] + b.box.boxMax[axis]; });
  Build(leaves, begin, middle);
  m_nodeRight[node] = Build(leaves, middle, end);
  return node;
}
