#include "SdfLeafTracer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

using LiteMath::float3;
using LiteMath::float4;

namespace
{
constexpr int kNewtonIterations = 4;

float3 Xyz(float4 v) { return float3(v.x, v.y, v.z); }

// The ray's span in the box [lo, hi] within [near, far]: false when it misses. A ray in a face's
// plane (0 * inf) keeps the other axes' span (litesdf::RayBox).
bool Span(float3 org, float3 dir, float3 lo, float3 hi, float near, float far, float& t0, float& t1)
{
  return litesdf::RayBox(org, float3(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z), lo, hi, near, far, t0, t1);
}

// Records h as the hit when it is nearer than the hit so far.
void Record(const litesdf::SdfHit& h, const CRT_LeafInfo& info, CRT_Hit& hit)
{
  if (h.t >= 0.0f && h.t < hit.t)
  {
    hit.t = h.t;
    hit.primId = info.aabbId;
    hit.instId = info.instId;
    hit.geomId = info.geomId;
    hit.coords[0] = h.normal.x;
    hit.coords[1] = h.normal.y;
    hit.coords[2] = h.normal.z;
  }
}
}  // namespace

void SdfGridGeom::Intersect(float4 posAndNear, float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit, const SdfLeafScene* scene) const
{
  const uint32_t bx = info.aabbId % bricksPerAxis, by = (info.aabbId / bricksPerAxis) % bricksPerAxis, bz = info.aabbId / (bricksPerAxis * bricksPerAxis);
  const float cell = boxMinAndCell.w, edge = cell * float(brickCells);
  const float3 corner = Xyz(boxMinAndCell) + edge * float3(float(bx), float(by), float(bz));
  float t0, t1;
  if (!Span(Xyz(posAndNear), Xyz(dirAndFar), corner, corner + float3(edge, edge, edge), posAndNear.w, hit.t, t0, t1))
    return;
  const uint32_t first = firstValue + ((bz * samples + by) * samples + bx) * brickCells;
  Record(scene->MarchBrick(corner, cell, int(brickCells), first, samples, samples * samples, Xyz(posAndNear), Xyz(dirAndFar), t0, t1), info, hit);
}

void SdfSVSGeom::Intersect(float4 posAndNear, float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit, const SdfLeafScene* scene) const
{
  const uint32_t voxel = firstVoxel + info.aabbId;
  const float4 box = scene->m_voxels[voxel];
  float t0, t1;
  if (!Span(Xyz(posAndNear), Xyz(dirAndFar), Xyz(box), Xyz(box) + float3(box.w, box.w, box.w), posAndNear.w, hit.t, t0, t1))
    return;
  litesdf::VoxelValues values;
  for (uint32_t c = 0; c < 8; ++c)
    values.v[c] = scene->m_voxelValues[8 * voxel + c];
  Record(litesdf::IntersectVoxelSpan(values, Xyz(box), box.w, Xyz(posAndNear), Xyz(dirAndFar), t0, t1, kNewtonIterations), info, hit);
}

void SdfSBSGeom::Intersect(float4 posAndNear, float4 dirAndFar, CRT_LeafInfo info, CRT_Hit& hit, const SdfLeafScene* scene) const
{
  const uint32_t brick = firstBrick + info.aabbId;
  const float4 box = scene->m_bricks[brick];
  const float edge = box.w * float(brickSize);
  float t0, t1;
  if (!Span(Xyz(posAndNear), Xyz(dirAndFar), Xyz(box), Xyz(box) + float3(edge, edge, edge), posAndNear.w, hit.t, t0, t1))
    return;
  const uint32_t side = brickSize + 1;
  Record(scene->MarchBrick(Xyz(box), box.w, int(brickSize), scene->m_brickValues[brick], side, side * side, Xyz(posAndNear), Xyz(dirAndFar), t0, t1),
         info, hit);
}

litesdf::SdfHit SdfLeafScene::MarchBrick(float3 corner, float cell, int n, uint32_t first, uint32_t strideY, uint32_t strideZ, float3 org, float3 dir,
                                         float t0, float t1) const
{
  // The cells in order along the ray (Amanatides and Woo), each tested until one is hit.
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
    const litesdf::SdfHit h = litesdf::IntersectVoxelSpan(values, cellMin, cell, org, dir, tEnter, std::min(tNext[a], t1), kNewtonIterations);
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

// The traversal (paper 3.10, listing 2): the tree's nodes the ray meets, nearer than the nearest
// hit so far; at each leaf, its field's intersection function.
CRT_Hit SdfLeafScene::RayQuery_NearestHit(float4 posAndNear, float4 dirAndFar)
{
  CRT_Hit hit;
  hit.t = dirAndFar.w;
  hit.primId = 0xFFFFFFFFu;
  hit.instId = 0xFFFFFFFFu;
  hit.geomId = 0xFFFFFFFFu;
  for (int i = 0; i < 4; ++i)
    hit.coords[i] = 0.0f;
  const float3 org = Xyz(posAndNear), dir = Xyz(dirAndFar);
  uint32_t stack[64];
  int top = 0;
  if (!m_nodeMin.empty())
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
    info.instId = 0;
    info.geomId = m_leafIds[m_nodeLeaf[node] - 1].x;
    info.rayxId = 0;
    info.rayyId = 0;
    m_geom[info.geomId]->Intersect(posAndNear, dirAndFar, info, hit, this);
  }
  return hit;
}

// ---- Host only: adding fields, their boxes, the tree. ----

uint32_t SdfLeafScene::AddGrid(const litesdf::SdfGrid& grid, uint32_t brickCells)
{
  if (!litesdf::Problem(grid).empty() || brickCells == 0 || (grid.samples - 1) % brickCells != 0)
    throw std::invalid_argument("SdfLeafScene::AddGrid: the grid's cells per axis must be a multiple of the brick's");
  auto geom = std::make_shared<SdfGridGeom>();
  geom->boxMinAndCell = float4(grid.boxMin.x, grid.boxMin.y, grid.boxMin.z, grid.CellSize());
  geom->firstValue = uint32_t(m_values.size());
  geom->samples = grid.samples;
  geom->brickCells = brickCells;
  geom->bricksPerAxis = (grid.samples - 1) / brickCells;
  m_values.insert(m_values.end(), grid.values.begin(), grid.values.end());
  m_geom.push_back(geom);
  return uint32_t(m_geom.size() - 1);
}

uint32_t SdfLeafScene::AddSVS(const litesdf::SdfSVS& svs)
{
  auto geom = std::make_shared<SdfSVSGeom>();
  geom->firstVoxel = uint32_t(m_voxels.size());
  geom->voxelCount = uint32_t(svs.VoxelCount());
  for (size_t i = 0; i < svs.VoxelCount(); ++i)
  {
    const float3 lo = svs.VoxelMin(i);
    m_voxels.push_back(float4(lo.x, lo.y, lo.z, svs.VoxelSize()));
    const litesdf::VoxelValues v = svs.Values(i);
    m_voxelValues.insert(m_voxelValues.end(), v.v, v.v + 8);
  }
  m_geom.push_back(geom);
  return uint32_t(m_geom.size() - 1);
}

uint32_t SdfLeafScene::AddSBS(const litesdf::SdfSBS& sbs)
{
  auto geom = std::make_shared<SdfSBSGeom>();
  geom->firstBrick = uint32_t(m_bricks.size());
  geom->brickSize = sbs.brickSize;
  geom->brickCount = uint32_t(sbs.BrickCount());
  const uint32_t b = sbs.brickSize;
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
  }
  m_geom.push_back(geom);
  return uint32_t(m_geom.size() - 1);
}

std::vector<CRT_AABB> SdfLeafScene::LeafBoxes(uint32_t geomId) const
{
  std::vector<CRT_AABB> boxes;
  auto box = [&](float3 lo, float edge) { boxes.push_back({float4(lo.x, lo.y, lo.z, 0.0f), float4(lo.x + edge, lo.y + edge, lo.z + edge, 0.0f)}); };
  const ISdfGeom* geom = m_geom.at(geomId).get();
  if (auto* grid = dynamic_cast<const SdfGridGeom*>(geom))
  {
    const uint32_t n = grid->bricksPerAxis;
    const float edge = grid->boxMinAndCell.w * float(grid->brickCells);
    for (uint32_t i = 0; i < n * n * n; ++i)
      box(Xyz(grid->boxMinAndCell) + edge * float3(float(i % n), float(i / n % n), float(i / (n * n))), edge);
  }
  else if (auto* svs = dynamic_cast<const SdfSVSGeom*>(geom))
  {
    for (uint32_t v = svs->firstVoxel; v < svs->firstVoxel + svs->voxelCount; ++v)
      box(Xyz(m_voxels[v]), m_voxels[v].w);
  }
  else if (auto* sbs = dynamic_cast<const SdfSBSGeom*>(geom))
  {
    for (uint32_t b = sbs->firstBrick; b < sbs->firstBrick + sbs->brickCount; ++b)
      box(Xyz(m_bricks[b]), m_bricks[b].w * float(sbs->brickSize));
  }
  return boxes;
}

void SdfLeafScene::Commit()
{
  std::vector<Leaf> leaves;
  for (uint32_t g = 0; g < m_geom.size(); ++g)
  {
    const std::vector<CRT_AABB> boxes = LeafBoxes(g);
    for (uint32_t i = 0; i < boxes.size(); ++i)
      leaves.push_back({boxes[i], g, i});
  }
  m_nodeMin.clear();
  m_nodeMax.clear();
  m_nodeRight.clear();
  m_nodeLeaf.clear();
  m_leafIds.clear();
  if (!leaves.empty())
    Build(leaves, 0, leaves.size());
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
    m_leafIds.push_back(LiteMath::uint2(leaves[begin].geomId, leaves[begin].aabbId));
    m_nodeLeaf[node] = uint32_t(m_leafIds.size());
    return node;
  }
  const float4 extent = hi - lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  const size_t middle = (begin + end) / 2;
  std::nth_element(leaves.begin() + begin, leaves.begin() + middle, leaves.begin() + end,
                   [axis](const Leaf& a, const Leaf& b) { return a.box.boxMin[axis] + a.box.boxMax[axis] < b.box.boxMin[axis] + b.box.boxMax[axis]; });
  Build(leaves, begin, middle);
  m_nodeRight[node] = Build(leaves, middle, end);
  return node;
}

void SdfLeafTracer::Trace(int n, const float4* origins, const float4* dirs, CRT_Hit* hits) { kernel1D_Trace(n, origins, dirs, hits); }

void SdfLeafTracer::kernel1D_Trace(int n, const float4* origins, const float4* dirs, CRT_Hit* hits)
{
  for (int i = 0; i < n; ++i)
    hits[i] = m_scene->RayQuery_NearestHit(origins[i], dirs[i]);
}
