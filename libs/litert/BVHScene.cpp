#include "BVHScene.h"

#include "SceneInput.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

using LiteMath::Box4f;
using LiteMath::float3;
using LiteMath::float4;
using LiteMath::float4x4;

namespace {

constexpr uint32_t kNoId = 0xFFFFFFFFu;
constexpr int kStackSize = 64;  // LBVH trees have at most 31 levels; the SAH builder stops at depth 48

// The slab test widens the far distance by 2 gamma(3) (Ize 2013, "Robust BVH Ray Traversal"), so
// rounding in the reciprocal never culls a box the exact ray touches: 1 + 3 ulp.
constexpr float kWiden = 1.00000036f;
static_assert(kWiden == 1.0f + 2.0f * (3.0f * std::numeric_limits<float>::epsilon() * 0.5f) /
                                   (1.0f - 3.0f * std::numeric_limits<float>::epsilon() * 0.5f),
              "kWiden is 1 + 2 gamma(3)");
constexpr float kMissed = -1.0f;  // SlabEntry's answer for a box the ray misses (entries are >= 0)

BVHTraceRay Prepare(float3 org, float3 dir, float tnear)
{
  BVHTraceRay r;
  r.org = org;
  r.dir = dir;
  r.tnear = tnear;
  // Denormal components whose reciprocal overflows count as zero too: 0 * inf would be NaN.
  r.invDir = float3(std::isinf(1.0f / dir.x) ? 0.0f : 1.0f / dir.x, std::isinf(1.0f / dir.y) ? 0.0f : 1.0f / dir.y,
                    std::isinf(1.0f / dir.z) ? 0.0f : 1.0f / dir.z);
  r.anyZeroAxis = r.invDir.x == 0.0f || r.invDir.y == 0.0f || r.invDir.z == 0.0f;
  const float3 ad = float3(std::fabs(dir.x), std::fabs(dir.y), std::fabs(dir.z));
  r.kz = ad.x >= ad.y && ad.x >= ad.z ? 0 : ad.y >= ad.z ? 1 : 2;
  r.kx = r.kz == 2 ? 0 : r.kz + 1;
  r.ky = r.kx == 2 ? 0 : r.kx + 1;
  if (dir[r.kz] < 0.0f)
  {
    const int k = r.kx;  // swapping keeps the winding, so the edge tests' signs stay meaningful
    r.kx = r.ky;
    r.ky = k;
  }
  r.sx = dir[r.kx] / dir[r.kz];
  r.sy = dir[r.ky] / dir[r.kz];
  r.sz = 1.0f / dir[r.kz];
  return r;
}

// SlabEntry for rays with a zero direction component (rare): per axis. Such a ray is inside that
// slab when its origin is, boundaries included.
[[gnu::noinline]] float SlabEntryParallelAxes(const BVHTraceRay& r, const float3& lo, const float3& hi, float tfar)
{
  float tmin = r.tnear;
  float tmax = tfar;
  for (int a = 0; a < 3; ++a)
  {
    if (r.invDir[a] == 0.0f)
    {
      if (r.org[a] < lo[a] || r.org[a] > hi[a])
        return kMissed;
      continue;
    }
    const float t0 = (lo[a] - r.org[a]) * r.invDir[a];
    const float t1 = (hi[a] - r.org[a]) * r.invDir[a];
    tmin = std::max(tmin, std::min(t0, t1));
    tmax = std::min(tmax, std::max(t0, t1) * kWiden);
  }
  return tmin <= tmax ? tmin : kMissed;
}

// The entry distance into [lo, hi] along the ray within [tnear, tfar], or kMissed. Inlined into
// the traversal loop: it runs twice per step.
[[gnu::always_inline]] inline float SlabEntry(const BVHTraceRay& r, const float3& lo, const float3& hi, float tfar)
{
  if (r.anyZeroAxis)
    return SlabEntryParallelAxes(r, lo, hi, tfar);
  const float x0 = (lo.x - r.org.x) * r.invDir.x;
  const float x1 = (hi.x - r.org.x) * r.invDir.x;
  const float y0 = (lo.y - r.org.y) * r.invDir.y;
  const float y1 = (hi.y - r.org.y) * r.invDir.y;
  const float z0 = (lo.z - r.org.z) * r.invDir.z;
  const float z1 = (hi.z - r.org.z) * r.invDir.z;
  const float tmin = std::max(std::max(std::min(x0, x1), std::min(y0, y1)), std::max(std::min(z0, z1), r.tnear));
  const float tmax = std::min(std::min(std::min(std::max(x0, x1), std::max(y0, y1)), std::max(z0, z1)) * kWiden, tfar);
  return tmin <= tmax ? tmin : kMissed;
}

// a * b - c * d within 1.5 ulp (Kahan's algorithm): its sign is exact, which decides on which side
// of an edge a ray passes when the plain float products cancel.
float DifferenceOfProducts(float a, float b, float c, float d)
{
  const float cd = c * d;
  const float error = std::fma(-c, d, cd);
  return std::fma(a, b, -cd) + error;
}

// Watertight ray/triangle test, both sides. On a hit in [tnear, tfar] sets t and Embree-style
// barycentrics (u weights v1, v weights v2).
bool IntersectTriangle(const BVHTraceRay& r, const BVHTriangle& tri, float tfar, float& t, float& u, float& v)
{
  const float3 a = tri.v0 - r.org;
  const float3 b = tri.v1 - r.org;
  const float3 c = tri.v2 - r.org;
  const float ax = a[r.kx] - r.sx * a[r.kz];
  const float ay = a[r.ky] - r.sy * a[r.kz];
  const float bx = b[r.kx] - r.sx * b[r.kz];
  const float by = b[r.ky] - r.sy * b[r.kz];
  const float cx = c[r.kx] - r.sx * c[r.kz];
  const float cy = c[r.ky] - r.sy * c[r.kz];
  float eu = cx * by - cy * bx;
  float ev = ax * cy - ay * cx;
  float ew = bx * ay - by * ax;
  if (eu == 0.0f || ev == 0.0f || ew == 0.0f)
  {
    // On an edge in float: decide exactly, so that neighbouring triangles agree.
    eu = DifferenceOfProducts(cx, by, cy, bx);
    ev = DifferenceOfProducts(ax, cy, ay, cx);
    ew = DifferenceOfProducts(bx, ay, by, ax);
  }
  if ((eu < 0.0f || ev < 0.0f || ew < 0.0f) && (eu > 0.0f || ev > 0.0f || ew > 0.0f))
    return false;
  const float det = eu + ev + ew;
  if (det == 0.0f)
    return false;  // edge-on or degenerate
  const float az = r.sz * a[r.kz];
  const float bz = r.sz * b[r.kz];
  const float cz = r.sz * c[r.kz];
  const float distance = (eu * az + ev * bz + ew * cz) / det;
  if (!(distance >= r.tnear && distance <= tfar))
    return false;
  t = distance;
  u = ev / det;
  v = ew / det;
  return true;
}

float3 ToObjectPoint(const BVHInstance& inst, float3 p)
{
  const float4 h = float4(p.x, p.y, p.z, 1.0f);
  return float3(dot(inst.toObjectRow0, h), dot(inst.toObjectRow1, h), dot(inst.toObjectRow2, h));
}

float3 ToObjectVector(const BVHInstance& inst, float3 d)
{
  const float4 h = float4(d.x, d.y, d.z, 0.0f);
  return float3(dot(inst.toObjectRow0, h), dot(inst.toObjectRow1, h), dot(inst.toObjectRow2, h));
}

// ---- host side ----

// The same tree with every pair of children side by side, in depth-first order: one cache line
// holds both boxes a traversal step tests (the LBVH places siblings far apart).
BVHTree WithSiblingsAdjacent(const BVHTree& tree)
{
  if (tree.nodes.size() <= 1)
    return tree;
  BVHTree out;
  out.primIndices = tree.primIndices;
  out.nodes.reserve(tree.nodes.size());
  out.nodes.push_back(tree.nodes[0]);
  std::vector<std::pair<uint32_t, uint32_t>> todo = {{0u, 0u}};  // (old index, new index)
  while (!todo.empty())
  {
    const auto [from, to] = todo.back();
    todo.pop_back();
    const BVHNode& n = tree.nodes[from];
    if (n.left & kLeafFlag)
      continue;
    const uint32_t children = uint32_t(out.nodes.size());
    out.nodes.push_back(tree.nodes[n.left]);
    out.nodes.push_back(tree.nodes[n.right]);
    out.nodes[to].left = children;
    out.nodes[to].right = children + 1;
    todo.push_back({n.right, children + 1});
    todo.push_back({n.left, children});
  }
  return out;
}

// Appends `tree` to `nodes` with child indices moved by the append position and leaf ranges
// moved by firstPrim. Returns the root's index.
uint32_t AppendTree(std::vector<BVHNode>& nodes, const BVHTree& tree, uint32_t firstPrim)
{
  const uint32_t base = uint32_t(nodes.size());
  for (BVHNode n : tree.nodes)
  {
    if (n.left & kLeafFlag)
      n.left = kLeafFlag | ((n.left & ~kLeafFlag) + firstPrim);
    else
    {
      n.left += base;
      n.right += base;
    }
    nodes.push_back(n);
  }
  return base;
}

float3 TransformPoint(const float4x4& m, float3 p) { return to_float3(m * float4(p.x, p.y, p.z, 1.0f)); }

}  // namespace

BVHScene::BVHScene(std::string name, Builder builder) : m_name(std::move(name)), m_builder(std::move(builder)) {}

void BVHScene::ClearDeviceData()
{
  m_nodes.clear();
  m_instances.clear();
  m_triangles.clear();
  m_primIds.clear();
}

void BVHScene::ClearGeom()
{
  ClearScene();
  m_meshes.clear();
}

void BVHScene::SetMesh(Mesh& mesh, const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum,
                       size_t vByteStride)
{
  litert_detail::ValidateMesh(m_name.c_str(), vpos3f, vertNum, triIndices, indNum, vByteStride);
  const char* base = reinterpret_cast<const char*>(vpos3f);
  auto vertex = [&](uint32_t i) {
    float3 p;
    std::memcpy(&p, base + i * vByteStride, sizeof(float3));
    return p;
  };
  const int triCount = int(indNum / 3);
  std::vector<BVHTriangle> tris(triCount);
  std::vector<Box4f> boxes(triCount);
  for (int i = 0; i < triCount; ++i)
  {
    tris[i] = {vertex(triIndices[3 * i]), vertex(triIndices[3 * i + 1]), vertex(triIndices[3 * i + 2])};
    const float3 lo = min(tris[i].v0, min(tris[i].v1, tris[i].v2)), hi = max(tris[i].v0, max(tris[i].v1, tris[i].v2));
    boxes[i] = Box4f(float4(lo.x, lo.y, lo.z, 0.0f), float4(hi.x, hi.y, hi.z, 0.0f));
  }
  mesh.tree = triCount > 0 ? WithSiblingsAdjacent(m_builder(boxes.data(), triCount)) : BVHTree{};
  mesh.triangles.resize(mesh.tree.primIndices.size());
  for (size_t k = 0; k < mesh.tree.primIndices.size(); ++k)
    mesh.triangles[k] = tris[mesh.tree.primIndices[k]];
  ClearDeviceData();
}

uint32_t BVHScene::AddGeom_Triangles3f(const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum,
                                       uint32_t, size_t vByteStride)
{
  Mesh mesh;
  SetMesh(mesh, vpos3f, vertNum, triIndices, indNum, vByteStride);
  m_meshes.push_back(std::move(mesh));
  return uint32_t(m_meshes.size() - 1);
}

void BVHScene::UpdateGeom_Triangles3f(uint32_t geomId, const float* vpos3f, size_t vertNum, const uint32_t* triIndices,
                                      size_t indNum, uint32_t, size_t vByteStride)
{
  if (geomId >= m_meshes.size())
    throw std::out_of_range(m_name + "::UpdateGeom_Triangles3f: invalid geomId " + std::to_string(geomId));
  SetMesh(m_meshes[geomId], vpos3f, vertNum, triIndices, indNum, vByteStride);
}

void BVHScene::ClearScene()
{
  m_placed.clear();
  ClearDeviceData();
}

uint32_t BVHScene::AddInstance(uint32_t geomId, const float4x4& matrix)
{
  if (geomId >= m_meshes.size())
    throw std::out_of_range(m_name + "::AddInstance: invalid geomId " + std::to_string(geomId));
  m_placed.push_back({geomId, matrix, LiteMath::inverse4x4(matrix)});
  ClearDeviceData();
  return uint32_t(m_placed.size() - 1);
}

void BVHScene::UpdateInstance(uint32_t instanceId, const float4x4& matrix)
{
  if (instanceId >= m_placed.size())
    throw std::out_of_range(m_name + "::UpdateInstance: invalid instanceId " + std::to_string(instanceId));
  m_placed[instanceId].toWorld = matrix;
  m_placed[instanceId].toObject = LiteMath::inverse4x4(matrix);
  ClearDeviceData();
}

void BVHScene::CommitScene(uint32_t)
{
  ClearDeviceData();
  // World boxes of the instances whose meshes have triangles; the top tree indexes into `ids`.
  std::vector<Box4f> boxes;
  std::vector<uint32_t> ids;
  for (uint32_t i = 0; i < m_placed.size(); ++i)
  {
    const BVHTree& tree = m_meshes[m_placed[i].geomId].tree;
    if (tree.nodes.empty())
      continue;
    Box4f box;
    for (int corner = 0; corner < 8; ++corner)
    {
      const float3 lo = tree.nodes[0].boxMin, hi = tree.nodes[0].boxMax;
      const float3 p((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y, (corner & 4) ? hi.z : lo.z);
      const float3 w = TransformPoint(m_placed[i].toWorld, p);
      box.include(float4(w.x, w.y, w.z, 0.0f));
    }
    boxes.push_back(box);
    ids.push_back(i);
  }
  if (boxes.empty())
    return;  // nothing to hit: the device data stays empty
  const BVHTree top = m_builder(boxes.data(), int(boxes.size()));

  // Device data: the top tree first, so its root is node 0, then each mesh that has triangles.
  AppendTree(m_nodes, top, 0);
  std::vector<uint32_t> meshRoot(m_meshes.size(), kNoId);
  for (uint32_t g = 0; g < m_meshes.size(); ++g)
  {
    const Mesh& mesh = m_meshes[g];
    if (mesh.tree.nodes.empty())
      continue;
    meshRoot[g] = AppendTree(m_nodes, mesh.tree, uint32_t(m_triangles.size()));
    m_triangles.insert(m_triangles.end(), mesh.triangles.begin(), mesh.triangles.end());
    m_primIds.insert(m_primIds.end(), mesh.tree.primIndices.begin(), mesh.tree.primIndices.end());
  }
  for (uint32_t k : top.primIndices)
  {
    const Instance& placed = m_placed[ids[k]];
    BVHInstance inst;
    inst.toObjectRow0 = placed.toObject.get_row(0);
    inst.toObjectRow1 = placed.toObject.get_row(1);
    inst.toObjectRow2 = placed.toObject.get_row(2);
    inst.instId = ids[k];
    inst.geomId = placed.geomId;
    inst.root = meshRoot[placed.geomId];
    inst.unused = 0;
    m_instances.push_back(inst);
  }
}

bool BVHScene::ExportScene(CRT_SceneExport& out) const
{
  static_assert(sizeof(BVHTriangle) == 9 * sizeof(float), "a triangle is copied as 9 floats");
  out = CRT_SceneExport{};
  out.meshTriangles.resize(m_meshes.size());
  for (size_t g = 0; g < m_meshes.size(); ++g)
  {
    // Back from leaf order to the order AddGeom received (the primIds hits report).
    const Mesh& mesh = m_meshes[g];
    uint32_t count = 0;
    for (uint32_t id : mesh.tree.primIndices)
      count = std::max(count, id + 1);
    std::vector<float>& soup = out.meshTriangles[g];
    soup.assign(size_t(9) * count, 0.0f);
    for (size_t k = 0; k < mesh.triangles.size(); ++k)
      std::memcpy(&soup[size_t(9) * mesh.tree.primIndices[k]], &mesh.triangles[k], 9 * sizeof(float));
  }
  if (m_nodes.empty())
    return true;  // not committed, or nothing to hit: every query misses
  for (const Instance& placed : m_placed)
  {
    CRT_SceneExport::Instance inst;
    inst.geomId = placed.geomId;
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 4; ++col)
        inst.toWorldRows[4 * row + col] = placed.toWorld(row, col);
    out.instances.push_back(inst);
  }
  return true;
}

// ---- traversal: plain C++ in the translator's conventions (composed into GPU kernels) ----

// Visits the leaves of the mesh tree at `root` that the ray may reach, nearest box first, and
// tests their triangles. On a hit nearer than tfar: sets tfar and the hit's t, primId and
// barycentrics, and returns true (at the first hit when anyHit).
bool BVHScene::TraceMesh(const BVHTraceRay& ray, uint32_t root, bool anyHit, float& tfar, CRT_Hit& hit) const
{
  if (SlabEntry(ray, m_nodes[root].boxMin, m_nodes[root].boxMax, tfar) < 0.0f)
    return false;
  uint32_t stack[kStackSize];
  float stackEntry[kStackSize];  // entry distances, to skip subtrees beyond a hit found since
  int top = 0;
  uint32_t node = root;
  bool found = false;
  while (true)
  {
    const BVHNode& n = m_nodes[node];
    if ((n.left & kLeafFlag) != 0)
    {
      const uint32_t first = n.left & ~kLeafFlag;
      for (uint32_t j = first; j < first + n.right; ++j)
      {
        float t = 0.0f;
        float u = 0.0f;
        float v = 0.0f;
        if (!IntersectTriangle(ray, m_triangles[j], tfar, t, u, v))
          continue;
        found = true;
        tfar = t;
        hit.t = t;
        hit.primId = m_primIds[j];
        hit.coords[0] = u;
        hit.coords[1] = v;
        if (anyHit)
          return true;
      }
    }
    else
    {
      const BVHNode& l = m_nodes[n.left];
      const BVHNode& r = m_nodes[n.right];
      const float tl = SlabEntry(ray, l.boxMin, l.boxMax, tfar);
      const float tr = SlabEntry(ray, r.boxMin, r.boxMax, tfar);
      const bool hitL = tl >= 0.0f;
      const bool hitR = tr >= 0.0f;
      if (hitL && hitR)
      {
        const bool leftFirst = tl <= tr;
        stackEntry[top] = leftFirst ? tr : tl;
        stack[top] = leftFirst ? n.right : n.left;
        top = top + 1;
        node = leftFirst ? n.left : n.right;
        continue;
      }
      if (hitL || hitR)
      {
        node = hitL ? n.left : n.right;
        continue;
      }
    }
    // Pop the next subtree that may still hold something nearer than tfar.
    do
    {
      if (top == 0)
        return found;
      top = top - 1;
    } while (stackEntry[top] > tfar);
    node = stack[top];
  }
}

// The top tree's leaves hold instances: each is traced in its mesh's tree, in object space
// (affine maps keep t: the object-space ray is not renormalized). This loop and TraceMesh's walk
// the stack alike; a shared step function would take the stack arrays as GLSL inout parameters,
// which copy them on every call.
bool BVHScene::Trace(float4 posAndNear, float4 dirAndFar, bool anyHit, CRT_Hit& hit) const
{
  float tnear = 0.0f;
  float tfar = 0.0f;
  if (m_nodes.size() == 0 || !litert_detail::RayInterval(posAndNear, dirAndFar, tnear, tfar))
    return false;
  const float3 org = to_float3(posAndNear);
  const float3 dir = to_float3(dirAndFar);
  const BVHTraceRay worldRay = Prepare(org, dir, tnear);
  if (SlabEntry(worldRay, m_nodes[0].boxMin, m_nodes[0].boxMax, tfar) < 0.0f)
    return false;
  uint32_t stack[kStackSize];
  float stackEntry[kStackSize];
  int top = 0;
  uint32_t node = 0;
  bool found = false;
  while (true)
  {
    const BVHNode& n = m_nodes[node];
    if ((n.left & kLeafFlag) != 0)
    {
      const uint32_t first = n.left & ~kLeafFlag;
      for (uint32_t k = first; k < first + n.right; ++k)
      {
        const BVHInstance& inst = m_instances[k];
        const BVHTraceRay ray = Prepare(ToObjectPoint(inst, org), ToObjectVector(inst, dir), tnear);
        if (!TraceMesh(ray, inst.root, anyHit, tfar, hit))
          continue;
        found = true;
        hit.instId = inst.instId;
        hit.geomId = inst.geomId;
        if (anyHit)
          return true;
      }
    }
    else
    {
      const BVHNode& l = m_nodes[n.left];
      const BVHNode& r = m_nodes[n.right];
      const float tl = SlabEntry(worldRay, l.boxMin, l.boxMax, tfar);
      const float tr = SlabEntry(worldRay, r.boxMin, r.boxMax, tfar);
      const bool hitL = tl >= 0.0f;
      const bool hitR = tr >= 0.0f;
      if (hitL && hitR)
      {
        const bool leftFirst = tl <= tr;
        stackEntry[top] = leftFirst ? tr : tl;
        stack[top] = leftFirst ? n.right : n.left;
        top = top + 1;
        node = leftFirst ? n.left : n.right;
        continue;
      }
      if (hitL || hitR)
      {
        node = hitL ? n.left : n.right;
        continue;
      }
    }
    do
    {
      if (top == 0)
        return found;
      top = top - 1;
    } while (stackEntry[top] > tfar);
    node = stack[top];
  }
}

CRT_Hit BVHScene::RayQuery_NearestHit(float4 posAndNear, float4 dirAndFar)
{
  CRT_Hit hit;
  hit.t = dirAndFar.w;
  hit.primId = kNoId;
  hit.instId = kNoId;
  hit.geomId = kNoId;
  hit.coords[0] = 0.0f;
  hit.coords[1] = 0.0f;
  hit.coords[2] = 0.0f;
  hit.coords[3] = 0.0f;
  Trace(posAndNear, dirAndFar, false, hit);
  return hit;
}

bool BVHScene::RayQuery_AnyHit(float4 posAndNear, float4 dirAndFar)
{
  CRT_Hit unused;
  unused.t = dirAndFar.w;
  return Trace(posAndNear, dirAndFar, true, unused);
}
