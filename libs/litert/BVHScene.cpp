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

// A ray prepared for one tree: slab test reciprocals and the watertight test's shear (Woop,
// Benthin and Wald 2013, "Watertight Ray/Triangle Intersection").
struct TraceRay
{
  float3 org, dir, invDir;
  int kx, ky, kz;
  float sx, sy, sz;
  float tnear;
  bool zeroAxis[3];
  bool anyZeroAxis;
};

TraceRay Prepare(float3 org, float3 dir, float tnear)
{
  TraceRay r;
  r.org = org;
  r.dir = dir;
  r.tnear = tnear;
  for (int a = 0; a < 3; ++a)
  {
    // Denormal components whose reciprocal overflows count as zero too: 0 * inf would be NaN.
    r.zeroAxis[a] = dir[a] == 0.0f || std::isinf(1.0f / dir[a]);
    r.invDir[a] = r.zeroAxis[a] ? 0.0f : 1.0f / dir[a];
  }
  r.anyZeroAxis = r.zeroAxis[0] || r.zeroAxis[1] || r.zeroAxis[2];
  const float3 ad(std::fabs(dir.x), std::fabs(dir.y), std::fabs(dir.z));
  r.kz = ad.x >= ad.y && ad.x >= ad.z ? 0 : ad.y >= ad.z ? 1 : 2;
  r.kx = (r.kz + 1) % 3;
  r.ky = (r.kx + 1) % 3;
  if (dir[r.kz] < 0.0f)
    std::swap(r.kx, r.ky);  // keeps the winding, so the edge tests' signs stay meaningful
  r.sx = dir[r.kx] / dir[r.kz];
  r.sy = dir[r.ky] / dir[r.kz];
  r.sz = 1.0f / dir[r.kz];
  return r;
}

// The entry distance into [lo, hi] along the ray within [tnear, tfar], or +inf when missed. The far
// distance is widened by 2 gamma(3) (Ize 2013, "Robust BVH Ray Traversal"), so rounding in the
// reciprocal never culls a box the exact ray touches. A ray parallel to an axis (direction +0 or
// -0) is inside that slab when its origin is, boundaries included.
constexpr float kWiden = 1.0f + 2.0f * (3.0f * std::numeric_limits<float>::epsilon() * 0.5f) /
                                    (1.0f - 3.0f * std::numeric_limits<float>::epsilon() * 0.5f);
constexpr float kMissed = std::numeric_limits<float>::infinity();

// SlabEntry for rays with a zero direction component (rare): per axis, with the in-slab test.
[[gnu::noinline]] float SlabEntryParallelAxes(const TraceRay& r, const float3& lo, const float3& hi, float tfar)
{
  float tmin = r.tnear, tmax = tfar;
  for (int a = 0; a < 3; ++a)
  {
    if (r.zeroAxis[a])
    {
      if (r.org[a] < lo[a] || r.org[a] > hi[a])
        return kMissed;
      continue;
    }
    float t0 = (lo[a] - r.org[a]) * r.invDir[a], t1 = (hi[a] - r.org[a]) * r.invDir[a];
    if (t0 > t1)
      std::swap(t0, t1);
    tmin = std::max(tmin, t0);
    tmax = std::min(tmax, t1 * kWiden);
  }
  return tmin <= tmax ? tmin : kMissed;
}

// Inlined into the traversal loop: it runs twice per step.
[[gnu::always_inline]] inline float SlabEntry(const TraceRay& r, const float3& lo, const float3& hi, float tfar)
{
  if (r.anyZeroAxis)
    return SlabEntryParallelAxes(r, lo, hi, tfar);
  const float x0 = (lo.x - r.org.x) * r.invDir.x, x1 = (hi.x - r.org.x) * r.invDir.x;
  const float y0 = (lo.y - r.org.y) * r.invDir.y, y1 = (hi.y - r.org.y) * r.invDir.y;
  const float z0 = (lo.z - r.org.z) * r.invDir.z, z1 = (hi.z - r.org.z) * r.invDir.z;
  const float tmin = std::max(std::max(std::min(x0, x1), std::min(y0, y1)), std::max(std::min(z0, z1), r.tnear));
  const float tmax = std::min(std::min(std::min(std::max(x0, x1), std::max(y0, y1)), std::max(z0, z1)) * kWiden, tfar);
  return tmin <= tmax ? tmin : kMissed;
}

// Watertight ray/triangle test, both sides. On a hit in [tnear, tfar] sets t and Embree-style
// barycentrics (u weights v1, v weights v2).
bool IntersectTriangle(const TraceRay& r, const BVHScene::Triangle& tri, float tfar, float& t, float& u, float& v)
{
  const float3 a = tri.v0 - r.org, b = tri.v1 - r.org, c = tri.v2 - r.org;
  const float ax = a[r.kx] - r.sx * a[r.kz], ay = a[r.ky] - r.sy * a[r.kz];
  const float bx = b[r.kx] - r.sx * b[r.kz], by = b[r.ky] - r.sy * b[r.kz];
  const float cx = c[r.kx] - r.sx * c[r.kz], cy = c[r.ky] - r.sy * c[r.kz];
  float eu = cx * by - cy * bx, ev = ax * cy - ay * cx, ew = bx * ay - by * ax;
  if (eu == 0.0f || ev == 0.0f || ew == 0.0f)
  {
    // On an edge in float: decide in double so that neighbouring triangles agree.
    eu = float(double(cx) * double(by) - double(cy) * double(bx));
    ev = float(double(ax) * double(cy) - double(ay) * double(cx));
    ew = float(double(bx) * double(ay) - double(by) * double(ax));
  }
  if ((eu < 0.0f || ev < 0.0f || ew < 0.0f) && (eu > 0.0f || ev > 0.0f || ew > 0.0f))
    return false;
  const float det = eu + ev + ew;
  if (det == 0.0f)
    return false;  // edge-on or degenerate
  const float az = r.sz * a[r.kz], bz = r.sz * b[r.kz], cz = r.sz * c[r.kz];
  const float distance = (eu * az + ev * bz + ew * cz) / det;
  if (!(distance >= r.tnear && distance <= tfar))
    return false;
  t = distance;
  u = ev / det;
  v = ew / det;
  return true;
}

// Visits the leaves of `tree` that the ray may reach, nearest box first. `leaf(first, count, tfar)`
// tests a leaf's primitives and returns the new tfar (smaller after a hit), or a negative value to stop.
template <typename LeafFn>
void Traverse(const BVHTree& tree, const TraceRay& ray, float tfar, LeafFn&& leaf)
{
  if (tree.nodes.empty() || SlabEntry(ray, tree.nodes[0].boxMin, tree.nodes[0].boxMax, tfar) > tfar)
    return;
  uint32_t stack[kStackSize];
  float stackEntry[kStackSize];  // entry distances, to skip subtrees beyond a hit found since
  int top = 0;
  uint32_t node = 0;
  while (true)
  {
    const BVHNode& n = tree.nodes[node];
    if (n.left & kLeafFlag)
    {
      tfar = leaf(n.left & ~kLeafFlag, n.right, tfar);
      if (tfar < 0.0f)
        return;
    }
    else
    {
      const BVHNode &l = tree.nodes[n.left], &r = tree.nodes[n.right];
      const float tl = SlabEntry(ray, l.boxMin, l.boxMax, tfar), tr = SlabEntry(ray, r.boxMin, r.boxMax, tfar);
      const bool hitL = tl <= tfar, hitR = tr <= tfar;
      if (hitL && hitR)
      {
        const bool leftFirst = tl <= tr;
        stackEntry[top] = leftFirst ? tr : tl;
        stack[top++] = leftFirst ? n.right : n.left;
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
        return;
      --top;
    } while (stackEntry[top] > tfar);
    node = stack[top];
  }
}

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

float3 TransformPoint(const float4x4& m, float3 p) { return to_float3(m * float4(p.x, p.y, p.z, 1.0f)); }
float3 TransformVector(const float4x4& m, float3 d) { return to_float3(m * float4(d.x, d.y, d.z, 0.0f)); }

}  // namespace

BVHScene::BVHScene(std::string name, Builder builder) : m_name(std::move(name)), m_builder(std::move(builder)) {}

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
  std::vector<Triangle> tris(triCount);
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
  m_committed = false;
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
  m_instances.clear();
  m_top = BVHTree{};
  m_committed = false;
}

uint32_t BVHScene::AddInstance(uint32_t geomId, const float4x4& matrix)
{
  if (geomId >= m_meshes.size())
    throw std::out_of_range(m_name + "::AddInstance: invalid geomId " + std::to_string(geomId));
  m_instances.push_back({geomId, matrix, LiteMath::inverse4x4(matrix)});
  m_committed = false;
  return uint32_t(m_instances.size() - 1);
}

void BVHScene::UpdateInstance(uint32_t instanceId, const float4x4& matrix)
{
  if (instanceId >= m_instances.size())
    throw std::out_of_range(m_name + "::UpdateInstance: invalid instanceId " + std::to_string(instanceId));
  m_instances[instanceId].toWorld = matrix;
  m_instances[instanceId].toObject = LiteMath::inverse4x4(matrix);
  m_committed = false;
}

void BVHScene::CommitScene(uint32_t)
{
  // World boxes of the instances whose meshes have triangles; the top tree indexes into `ids`.
  std::vector<Box4f> boxes;
  std::vector<uint32_t> ids;
  for (uint32_t i = 0; i < m_instances.size(); ++i)
  {
    const BVHTree& tree = m_meshes[m_instances[i].geomId].tree;
    if (tree.nodes.empty())
      continue;
    Box4f box;
    for (int corner = 0; corner < 8; ++corner)
    {
      const float3 lo = tree.nodes[0].boxMin, hi = tree.nodes[0].boxMax;
      const float3 p((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y, (corner & 4) ? hi.z : lo.z);
      const float3 w = TransformPoint(m_instances[i].toWorld, p);
      box.include(float4(w.x, w.y, w.z, 0.0f));
    }
    boxes.push_back(box);
    ids.push_back(i);
  }
  m_top = boxes.empty() ? BVHTree{} : m_builder(boxes.data(), int(boxes.size()));
  for (uint32_t& p : m_top.primIndices)
    p = ids[p];
  m_committed = true;
}

template <bool anyHit>
bool BVHScene::Trace(float4 posAndNear, float4 dirAndFar, CRT_Hit& hit) const
{
  float tnear = 0.0f, tfar = 0.0f;
  if (!m_committed || !litert_detail::RayInterval(posAndNear, dirAndFar, tnear, tfar))
    return false;
  const float3 org = to_float3(posAndNear), dir = to_float3(dirAndFar);
  const TraceRay worldRay = Prepare(org, dir, tnear);
  bool found = false;
  Traverse(m_top, worldRay, tfar, [&](uint32_t first, uint32_t count, float instFar) {
    for (uint32_t k = first; k < first + count; ++k)
    {
      const Instance& inst = m_instances[m_top.primIndices[k]];
      const Mesh& mesh = m_meshes[inst.geomId];
      // Affine maps keep t: the object-space ray is not renormalized.
      const TraceRay ray = Prepare(TransformPoint(inst.toObject, org), TransformVector(inst.toObject, dir), tnear);
      Traverse(mesh.tree, ray, instFar, [&](uint32_t firstTri, uint32_t triCount, float triFar) {
        for (uint32_t j = firstTri; j < firstTri + triCount; ++j)
        {
          float t, u, v;
          if (!IntersectTriangle(ray, mesh.triangles[j], triFar, t, u, v))
            continue;
          found = true;
          if (anyHit)
            return -1.0f;
          triFar = t;
          hit.t = t;
          hit.primId = mesh.tree.primIndices[j];
          hit.instId = m_top.primIndices[k];
          hit.geomId = inst.geomId;
          hit.coords[0] = u;
          hit.coords[1] = v;
        }
        return triFar;
      });
      if (anyHit && found)
        return -1.0f;
      instFar = found ? hit.t : instFar;
    }
    return instFar;
  });
  return found;
}

CRT_Hit BVHScene::RayQuery_NearestHit(float4 posAndNear, float4 dirAndFar)
{
  CRT_Hit hit;
  hit.t = dirAndFar.w;
  hit.primId = hit.instId = hit.geomId = kNoId;
  hit.coords[0] = hit.coords[1] = hit.coords[2] = hit.coords[3] = 0.0f;
  Trace<false>(posAndNear, dirAndFar, hit);
  return hit;
}

bool BVHScene::RayQuery_AnyHit(float4 posAndNear, float4 dirAndFar)
{
  CRT_Hit unused;
  return Trace<true>(posAndNear, dirAndFar, unused);
}
