#include "BVHScene.h"

#include "Gang.h"
#include "SceneInput.h"
#include "SdfStructures.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#if defined(__linux__)
#include <sys/mman.h>
#endif

using LiteMath::as_float;
using LiteMath::Box4f;
using LiteMath::clamp;
using LiteMath::float3;
using LiteMath::float3x3;
using LiteMath::float4;
using LiteMath::float4x4;
using LiteMath::inverse;
using LiteMath::make_float3x3_from_rows;
using LiteMath::mix;
using LiteMath::uint4;

namespace {

constexpr uint32_t kNoId = 0xFFFFFFFFu;
constexpr int kStackSize = 64;  // LBVH trees have at most 31 levels; the SAH builder stops at depth 48

// The slab test widens the far distance by 2 gamma(3) (Ize 2013, "Robust BVH Ray Traversal"), so
// rounding in the reciprocal never culls a box the exact ray touches: 1 + 3 ulp.
constexpr float kWiden = 1.00000036f;
static_assert(kWiden == 1.0f + 2.0f * (3.0f * std::numeric_limits<float>::epsilon() * 0.5f) /
                                   (1.0f - 3.0f * std::numeric_limits<float>::epsilon() * 0.5f),
              "kWiden is 1 + 2 gamma(3)");
// How far past tfar the walks still enter a box: its entry and a hit's t are rounded apart, and a
// hit at a vertex or an edge lies on the boxes of the leaves around it. With this slack every
// triangle a ray meets at its nearest t is tested, whichever leaf a walk reaches first, so the lowest
// primId among them wins in every walk (TakeNearestHit): the scalar one, the gang's and a GPU's.
// 1 + 2^-19, about 16 ulp: more than the few rounding steps of each side.
constexpr float kReach = 1.0f + 1.0f / 524288.0f;
inline float Reach(float tfar) { return tfar * kReach; }
constexpr float kMissed = -1.0f;  // an exit before every entry (entries are >= 0): a missed box
constexpr float kNotEntered = std::numeric_limits<float>::infinity();  // a ray's entry into a subtree it does not enter

// The ray of lane `from` in each lane (crossrt::FromLane, field by field): a lane that works for
// another lane's ray (TraceMeshQuads) takes that ray whole.
BVHTraceRay RayFromLane(const BVHTraceRay& ray, int from)
{
  BVHTraceRay r;
  r.org = float3(crossrt::FromLane(ray.org.x, from), crossrt::FromLane(ray.org.y, from), crossrt::FromLane(ray.org.z, from));
  r.dir = float3(crossrt::FromLane(ray.dir.x, from), crossrt::FromLane(ray.dir.y, from), crossrt::FromLane(ray.dir.z, from));
  r.invDir = float3(crossrt::FromLane(ray.invDir.x, from), crossrt::FromLane(ray.invDir.y, from), crossrt::FromLane(ray.invDir.z, from));
  r.tnear = crossrt::FromLane(ray.tnear, from);
  r.kx = crossrt::FromLane(ray.kx, from);
  r.ky = crossrt::FromLane(ray.ky, from);
  r.kz = crossrt::FromLane(ray.kz, from);
  r.sx = crossrt::FromLane(ray.sx, from);
  r.sy = crossrt::FromLane(ray.sy, from);
  r.sz = crossrt::FromLane(ray.sz, from);
  r.anyZeroAxis = crossrt::FromLane(ray.anyZeroAxis, from);
  return r;
}

// p's coordinates along the axes kx, ky and kz, as a triangle's corners are given to IntersectCorners.
// Selects, so that lanes whose rays run along different axes pick theirs from the same loads.
float3 AlongAxes(float3 p, int kx, int ky, int kz)
{
  return float3(kx == 0 ? p.x : kx == 1 ? p.y : p.z, ky == 0 ? p.x : ky == 1 ? p.y : p.z, kz == 0 ? p.x : kz == 1 ? p.y : p.z);
}

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
  const int kx = r.kz == 2 ? 0 : r.kz + 1;
  const int ky = kx == 2 ? 0 : kx + 1;
  // Swapped where the ray runs down its major axis: that keeps the winding, so the edge tests'
  // signs stay meaningful. Selects, not a branch: a store to a field of a local struct under a
  // condition that differs between SIMD lanes is a masked store to memory on ISPC.
  const bool swap = dir[r.kz] < 0.0f;
  r.kx = swap ? ky : kx;
  r.ky = swap ? kx : ky;
  r.sx = dir[r.kx] / dir[r.kz];
  r.sy = dir[r.ky] / dir[r.kz];
  r.sz = 1.0f / dir[r.kz];
  return r;
}

// The entry (returned) and exit distances of a ray with a zero direction component (rare) into the
// box [lo, hi], within [tnear, tfar]: per axis. Such a ray is inside a slab when its origin is,
// boundaries included. A box whose entry is beyond its exit is missed (so is an empty box).
inline float SlabEntryParallelAxes(const BVHTraceRay& r, float3 lo, float3 hi, float tfar, float& exit)
{
  float tmin = r.tnear;
  float tmax = tfar;
  bool inside = lo.x <= hi.x;  // an empty lane is never entered
  for (int a = 0; a < 3; ++a)
  {
    if (r.invDir[a] == 0.0f)
    {
      inside = inside && r.org[a] >= lo[a] && r.org[a] <= hi[a];
      continue;
    }
    const float t0 = (lo[a] - r.org[a]) * r.invDir[a];
    const float t1 = (hi[a] - r.org[a]) * r.invDir[a];
    tmin = std::max(tmin, std::min(t0, t1));
    tmax = std::min(tmax, std::max(t0, t1) * kWiden);
  }
  exit = inside ? tmax : kMissed;
  return inside ? tmin : 0.0f;
}

// The same for the four boxes of `n`.
[[gnu::noinline]] float4 SlabEntriesParallelAxes(const BVHTraceRay& r, const BVH4Node& n, float tfar, float4& exits)
{
  float4 entries = float4(0.0f);
  for (int lane = 0; lane < 4; ++lane)
  {
    float exit = 0.0f;
    entries[lane] = SlabEntryParallelAxes(r, float3(n.minX[lane], n.minY[lane], n.minZ[lane]), float3(n.maxX[lane], n.maxY[lane], n.maxZ[lane]),
                                          tfar, exit);
    exits[lane] = exit;
  }
  return entries;
}

// SlabEntriesParallelAxes for every other ray, four boxes at once: each axis' near plane is the
// box side the ray faces, so an empty lane (+inf, -inf) enters at +inf and exits at -inf.
[[gnu::always_inline]] inline float4 SlabEntries(const BVHTraceRay& r, const BVH4Node& n, float tfar, float4& exits)
{
  if (r.anyZeroAxis)
    return SlabEntriesParallelAxes(r, n, tfar, exits);
  const float4 nearX = ((r.invDir.x < 0.0f ? n.maxX : n.minX) - r.org.x) * r.invDir.x;
  const float4 farX = ((r.invDir.x < 0.0f ? n.minX : n.maxX) - r.org.x) * r.invDir.x;
  const float4 nearY = ((r.invDir.y < 0.0f ? n.maxY : n.minY) - r.org.y) * r.invDir.y;
  const float4 farY = ((r.invDir.y < 0.0f ? n.minY : n.maxY) - r.org.y) * r.invDir.y;
  const float4 nearZ = ((r.invDir.z < 0.0f ? n.maxZ : n.minZ) - r.org.z) * r.invDir.z;
  const float4 farZ = ((r.invDir.z < 0.0f ? n.minZ : n.maxZ) - r.org.z) * r.invDir.z;
  exits = min(min(min(farX, farY), farZ) * kWiden, float4(tfar));
  return max(max(nearX, nearY), max(nearZ, float4(r.tnear)));
}

// SlabEntry's arithmetic, given the planes a ray meets first (nearPlanes) and last along each axis.
[[gnu::always_inline]] inline float SlabEntryFacing(const BVHTraceRay& r, float3 nearPlanes, float3 farPlanes, float tfar, float& exit)
{
  const float nearX = (nearPlanes.x - r.org.x) * r.invDir.x;
  const float farX = (farPlanes.x - r.org.x) * r.invDir.x;
  const float nearY = (nearPlanes.y - r.org.y) * r.invDir.y;
  const float farY = (farPlanes.y - r.org.y) * r.invDir.y;
  const float nearZ = (nearPlanes.z - r.org.z) * r.invDir.z;
  const float farZ = (farPlanes.z - r.org.z) * r.invDir.z;
  exit = std::min(std::min(std::min(farX, farY), farZ) * kWiden, tfar);
  return std::max(std::max(nearX, nearY), std::max(nearZ, r.tnear));
}

// One box of a node, [lo, hi], as SlabEntries and SlabEntriesParallelAxes test a lane of four: the
// same arithmetic, so the same entry (returned) and exit. Packet traversal tests a node's boxes one
// at a time against its gang's rays: four at once hold eight values per ray, which spill AVX2's
// sixteen registers.
[[gnu::always_inline]] inline float SlabEntry(const BVHTraceRay& r, float3 lo, float3 hi, float tfar, float& exit)
{
  if (r.anyZeroAxis)
    return SlabEntryParallelAxes(r, lo, hi, tfar, exit);
  return SlabEntryFacing(r, float3(r.invDir.x < 0.0f ? hi.x : lo.x, r.invDir.y < 0.0f ? hi.y : lo.y, r.invDir.z < 0.0f ? hi.z : lo.z),
                         float3(r.invDir.x < 0.0f ? lo.x : hi.x, r.invDir.y < 0.0f ? lo.y : hi.y, r.invDir.z < 0.0f ? lo.z : hi.z), tfar, exit);
}

// Puts lanes i < j of (entries, children) in order of entry.
inline void OrderLanes(float4& entries, uint4& children, int i, int j)
{
  if (entries[j] < entries[i])
  {
    const float e = entries[i];
    entries[i] = entries[j];
    entries[j] = e;
    const uint32_t c = children[i];
    children[i] = children[j];
    children[j] = c;
  }
}

// The lanes of `n` the ray enters within [tnear, tfar], nearest first: their entry distances and
// children in entries/children[0, count), and count. Coherent rays mostly enter one or two lanes,
// so each count has its own path: no compare for one lane, one for two, a network for more.
inline int EnteredLanes(const BVHTraceRay& r, const BVH4Node& n, float tfar, float4& entries, uint4& children)
{
  float4 exits;
  const float4 laneEntries = SlabEntries(r, n, tfar, exits);
  uint32_t mask = lane_mask_le(laneEntries, exits);  // a NaN entry or exit compares false: missed
  if (mask == 0u)
    return 0;
  const int first = __builtin_ctz(mask);
  entries[0] = laneEntries[first];
  children[0] = n.child[first];
  mask = mask & (mask - 1u);
  if (mask == 0u)
    return 1;
  const int second = __builtin_ctz(mask);
  entries[1] = laneEntries[second];
  children[1] = n.child[second];
  OrderLanes(entries, children, 0, 1);
  mask = mask & (mask - 1u);
  if (mask == 0u)
    return 2;
  // Three or four: insert each into the ordered front.
  const int third = __builtin_ctz(mask);
  entries[2] = laneEntries[third];
  children[2] = n.child[third];
  OrderLanes(entries, children, 1, 2);
  OrderLanes(entries, children, 0, 1);
  mask = mask & (mask - 1u);
  if (mask == 0u)
    return 3;
  entries[3] = laneEntries[3];  // the fourth entered lane can only be lane 3
  children[3] = n.child[3];
  OrderLanes(entries, children, 2, 3);
  OrderLanes(entries, children, 1, 2);
  OrderLanes(entries, children, 0, 1);
  return 4;
}

// a * b - c * d within 1.5 ulp (Kahan's algorithm): its sign is exact, which decides on which side
// of an edge a ray passes when the plain float products cancel.
float DifferenceOfProducts(float a, float b, float c, float d)
{
  const float cd = c * d;
  const float error = std::fma(-c, d, cd);
  return std::fma(a, b, -cd) + error;
}

float4 DifferenceOfProducts(float4 a, float4 b, float4 c, float4 d)
{
  return float4(DifferenceOfProducts(a.x, b.x, c.x, d.x), DifferenceOfProducts(a.y, b.y, c.y, d.y),
                DifferenceOfProducts(a.z, b.z, c.z, d.z), DifferenceOfProducts(a.w, b.w, c.w, d.w));
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

constexpr uint32_t kMergeSize = 4;  // subtrees of up to this many primitives become one leaf

uint32_t LeafRef(uint32_t first, uint32_t count) { return kLeafFlag | first << 3 | (count - 1); }

// Collapses a binary tree into BVH4Nodes: each node takes its two children, then opens the child
// with the largest surface area (an inner node, or a leaf of more than leafSize primitives,
// which is halved) until it has four or nothing is left to open.
class Collapse
{
public:
  // primBox(k): the box of primitive tree.primIndices[k]. Leaves hold up to leafSize primitives, and
  // a subtree of up to min(leafSize, kMergeSize) consecutive ones becomes one leaf.
  Collapse(const BVHTree& tree, std::function<Box4f(uint32_t)> primBox, uint32_t leafSize)
      : m_tree(tree), m_primBox(std::move(primBox)), m_leafSize(leafSize), m_mergeSize(std::min(leafSize, kMergeSize))
  {
    m_first.resize(tree.nodes.size());
    m_count.resize(tree.nodes.size());
    Measure(0);
  }

  // Node 0 is the root. stackNeed: the most entries TraceMesh's stack holds on this tree.
  std::vector<BVH4Node> Run(int& stackNeed)
  {
    m_nodes.clear();
    Emit(FromBinary(0), stackNeed);
    return std::move(m_nodes);
  }

private:
  // A subtree to place in a lane: a binary inner node, or a range of primitives.
  struct Part
  {
    uint32_t node;  // kNoChild for a range
    uint32_t first, count;
    Box4f box;
  };

  // The primitive range under each binary node (count 0: not contiguous).
  void Measure(uint32_t index)
  {
    const BVHNode& n = m_tree.nodes[index];
    if (n.left & kLeafFlag)
    {
      m_first[index] = n.left & ~kLeafFlag;
      m_count[index] = n.right;
      return;
    }
    Measure(n.left);
    Measure(n.right);
    const uint32_t l = n.left, r = n.right;
    const bool contiguous = m_count[l] > 0 && m_count[r] > 0 && m_first[l] + m_count[l] == m_first[r];
    m_first[index] = m_first[l];
    m_count[index] = contiguous ? m_count[l] + m_count[r] : 0;
  }

  Part FromBinary(uint32_t index) const
  {
    const BVHNode& n = m_tree.nodes[index];
    const Box4f box(float4(n.boxMin, 0.0f), float4(n.boxMax, 0.0f));
    // A small subtree over consecutive primitives becomes one leaf: testing its few triangles
    // costs less than a step over their boxes.
    if ((n.left & kLeafFlag) || (m_count[index] > 0 && m_count[index] <= m_mergeSize))
      return {kNoChild, m_first[index], m_count[index], box};
    return {index, 0, 0, box};
  }

  Part Range(uint32_t first, uint32_t count) const
  {
    Part part{kNoChild, first, count, Box4f()};
    for (uint32_t k = first; k < first + count; ++k)
      part.box.include(m_primBox(k));
    return part;
  }

  bool Openable(const Part& p) const { return p.node != kNoChild || p.count > m_leafSize; }

  void Open(const Part& p, Part& a, Part& b) const
  {
    if (p.node != kNoChild)
    {
      a = FromBinary(m_tree.nodes[p.node].left);
      b = FromBinary(m_tree.nodes[p.node].right);
      return;
    }
    const uint32_t half = p.count / 2;
    a = Range(p.first, half);
    b = Range(p.first + half, p.count - half);
  }

  uint32_t Emit(const Part& part, int& stackNeed)
  {
    std::vector<Part> lanes;
    if (Openable(part))
    {
      lanes.resize(2);
      Open(part, lanes[0], lanes[1]);
    }
    else
      lanes.push_back(part);  // a root that is one small leaf
    while (lanes.size() < 4)
    {
      int widest = -1;
      for (int i = 0; i < int(lanes.size()); ++i)
        if (Openable(lanes[i]) && (widest < 0 || lanes[i].box.surfaceArea() > lanes[widest].box.surfaceArea()))
          widest = i;
      if (widest < 0)
        break;
      Part a, b;
      Open(lanes[widest], a, b);
      lanes[widest] = a;
      lanes.push_back(b);
    }
    const uint32_t index = uint32_t(m_nodes.size());
    m_nodes.emplace_back();
    BVH4Node n;
    n.minX = n.minY = n.minZ = float4(LiteMath::INF_POSITIVE);
    n.maxX = n.maxY = n.maxZ = float4(LiteMath::INF_NEGATIVE);
    n.child = LiteMath::uint4(kNoChild);
    n.unused = LiteMath::uint4(0u);
    int deepest = 0;  // the stack the lanes' subtrees need
    for (int i = 0; i < int(lanes.size()); ++i)
    {
      const Part& lane = lanes[i];
      n.minX[i] = lane.box.boxMin.x, n.minY[i] = lane.box.boxMin.y, n.minZ[i] = lane.box.boxMin.z;
      n.maxX[i] = lane.box.boxMax.x, n.maxY[i] = lane.box.boxMax.y, n.maxZ[i] = lane.box.boxMax.z;
      if (Openable(lane))
      {
        int need = 0;
        n.child[i] = Emit(lane, need);
        deepest = std::max(deepest, need);
      }
      else
        n.child[i] = LeafRef(lane.first, lane.count);
    }
    m_nodes[index] = n;
    // A step pushes every lane it enters and pops the nearest, leaving the others below it.
    stackNeed = std::max(int(lanes.size()), int(lanes.size()) - 1 + deepest);
    return index;
  }

  const BVHTree& m_tree;
  std::function<Box4f(uint32_t)> m_primBox;
  uint32_t m_leafSize, m_mergeSize;
  std::vector<uint32_t> m_first, m_count;
  std::vector<BVH4Node> m_nodes;
};

// Visits the leaves of `wide` in order, their entries in groups of four: open() starts a group
// and returns its index, fill(lane, k) puts entry k of the leaf's range in a lane of the open
// group, empty(lane) marks a lane the leaf does not fill; each leaf then points at its groups.
template <class Open, class Fill, class Empty>
void PackLeavesByFour(std::vector<BVH4Node>& wide, Open open, Fill fill, Empty empty)
{
  for (BVH4Node& n : wide)
    for (int lane = 0; lane < 4; ++lane)
    {
      const uint32_t c = n.child[lane];
      if (c == kNoChild || (c & kLeafFlag) == 0)
        continue;
      const uint32_t first = (c & ~kLeafFlag) >> 3, count = (c & 7u) + 1, groupCount = (count + 3) / 4;
      uint32_t firstGroup = 0;
      for (uint32_t k = 0; k < 4 * groupCount; ++k)
      {
        if (k % 4 == 0)
        {
          const uint32_t g = open();
          firstGroup = k == 0 ? g : firstGroup;
        }
        if (k < count)
          fill(k % 4, first + k);
        else
          empty(k % 4);
      }
      n.child[lane] = LeafRef(firstGroup, groupCount);
    }
}

// Packs the triangles of each leaf of `wide` (triangles[k] is triangle primIndices[k]) into groups
// of four, in the order the leaves appear (empty lanes NaN), and points the leaves at their groups.
void GroupLeaves(std::vector<BVH4Node>& wide, const std::vector<BVHTriangle>& triangles, const std::vector<uint32_t>& primIndices,
                 std::vector<BVHTriangle4>& groups, std::vector<uint32_t>& groupPrims)
{
  groups.clear();
  groupPrims.clear();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  PackLeavesByFour(
      wide,
      [&] {
        groups.emplace_back();
        for (float4& c4 : groups.back().coord) c4 = float4(nan);
        return uint32_t(groups.size() - 1);
      },
      [&](int slot, uint32_t k) {
        const BVHTriangle& tri = triangles[k];
        const float3 corners[3] = {tri.v0, tri.v1, tri.v2};
        for (int corner = 0; corner < 3; ++corner)
          for (int axis = 0; axis < 3; ++axis)
            groups.back().coord[3 * corner + axis][slot] = corners[corner][axis];
        groupPrims.push_back(primIndices[k]);
      },
      [&](int) { groupPrims.push_back(kNoId); });
}

// Box geometry: packs the boxes of each leaf of `wide` (boxes[k] is box primIndices[k]) into groups
// of four, laid out as a node's lanes (so that one slab test covers four), a lane's child the
// primitive its box bounds; points the leaves at their groups.
void GroupBoxes(std::vector<BVH4Node>& wide, const std::vector<Box4f>& boxes, const std::vector<uint32_t>& primIndices,
                uint32_t boxesPerPrim, std::vector<BVH4Node>& groups)
{
  groups.clear();
  const float inf = std::numeric_limits<float>::infinity();
  PackLeavesByFour(
      wide,
      [&] {
        groups.emplace_back();
        BVH4Node& g = groups.back();
        g.minX = g.minY = g.minZ = float4(inf);
        g.maxX = g.maxY = g.maxZ = float4(-inf);
        g.child = uint4(kNoChild);
        g.unused = uint4(0u);
        return uint32_t(groups.size() - 1);
      },
      [&](int slot, uint32_t k) {
        BVH4Node& g = groups.back();
        const Box4f& b = boxes[primIndices[k]];
        g.minX[slot] = b.boxMin.x;
        g.minY[slot] = b.boxMin.y;
        g.minZ[slot] = b.boxMin.z;
        g.maxX[slot] = b.boxMax.x;
        g.maxY[slot] = b.boxMax.y;
        g.maxZ[slot] = b.boxMax.z;
        g.child[slot] = primIndices[k] / boxesPerPrim;
      },
      [](int) {});
}

std::vector<BVH4Node> CollapseTree(const BVHTree& tree, std::function<Box4f(uint32_t)> primBox, uint32_t leafSize = kMaxLeafSize)
{
  int stackNeed = 0;
  std::vector<BVH4Node> nodes = Collapse(tree, std::move(primBox), leafSize).Run(stackNeed);
  if (stackNeed > kStackSize)
    throw std::length_error("BVHScene: the tree is too deep for the traversal's stack (" + std::to_string(stackNeed) + " entries, " +
                            std::to_string(kStackSize) + " available)");
  return nodes;
}

// Appends `tree` to `nodes` with child indices moved by the append position and leaf ranges
// (primitives or groups) moved by firstPrim. Returns the root's index.
uint32_t AppendTree(std::vector<BVH4Node>& nodes, const std::vector<BVH4Node>& tree, uint32_t firstPrim)
{
  const uint32_t base = uint32_t(nodes.size());
  for (BVH4Node n : tree)
  {
    for (int i = 0; i < 4; ++i)
    {
      const uint32_t c = n.child[i];
      if (c == kNoChild)
        continue;
      const uint32_t first = ((c & ~kLeafFlag) >> 3) + firstPrim;
      if ((c & kLeafFlag) && first >= (1u << 28))
        throw std::length_error("BVHScene: more than 2^28 groups of triangles in a scene");
      n.child[i] = (c & kLeafFlag) ? LeafRef(first, (c & 7u) + 1) : c + base;
    }
    nodes.push_back(n);
  }
  return base;
}

// Reserves room for count elements and, on Linux, asks for transparent huge pages (2 MiB) under
// it before anything is written there. The traversal reads nodes and triangles all over tens of
// megabytes; with 4 KiB pages most of those reads also miss the TLB. (Distributions leave huge
// pages to madvise. On the 871K-triangle dragon, PrimaryRays_ISPC's ratio to Embree rose 2-4%.)
template <class T>
void ReserveOnHugePages(std::vector<T>& v, size_t count)
{
  v.reserve(count);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHuge = uintptr_t(2) << 20;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(v.data()) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = reinterpret_cast<uintptr_t>(v.data() + count) & ~(kHuge - 1);
  if (end > begin)
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);  // advice only: no error to report
#endif
}

bool IsIdentity(const float4x4& m)
{
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col)
      if (m(row, col) != (row == col ? 1.0f : 0.0f))
        return false;
  return true;
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
  m_boxes.clear();
  m_motion.clear();
  m_sdfBricks.clear();
  m_sdfWords.clear();
  m_sceneKinds = 0;
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
  mesh = Mesh{};  // triangles now, whatever it was
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
  mesh.tree = triCount > 0 ? m_builder(boxes.data(), triCount) : BVHTree{};
  mesh.triangles.resize(mesh.tree.primIndices.size());
  for (size_t k = 0; k < mesh.tree.primIndices.size(); ++k)
    mesh.triangles[k] = tris[mesh.tree.primIndices[k]];
  mesh.wide.clear();
  if (triCount > 0)
    mesh.wide = CollapseTree(mesh.tree, [&](uint32_t k) { return boxes[mesh.tree.primIndices[k]]; });
  GroupLeaves(mesh.wide, mesh.triangles, mesh.tree.primIndices, mesh.groups, mesh.groupPrims);
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

void BVHScene::SetBoxes(Mesh& mesh, const CRT_AABB* boxes, size_t boxNumber, size_t customPrimCount)
{
  if (boxNumber > 0 && boxes == nullptr)
    throw std::invalid_argument(m_name + "::AddGeom_AABB: null boxes");
  if (customPrimCount > 0 && boxNumber % customPrimCount != 0)
    throw std::invalid_argument(m_name + "::AddGeom_AABB: " + std::to_string(boxNumber) + " boxes are not a multiple of " +
                                std::to_string(customPrimCount) + " primitives");
  std::vector<Box4f> bounds(boxNumber);
  for (size_t i = 0; i < boxNumber; ++i)
  {
    bounds[i] = Box4f(float4(boxes[i].boxMin.x, boxes[i].boxMin.y, boxes[i].boxMin.z, 0.0f),
                      float4(boxes[i].boxMax.x, boxes[i].boxMax.y, boxes[i].boxMax.z, 0.0f));
    if (!(bounds[i].boxMin.x <= bounds[i].boxMax.x && bounds[i].boxMin.y <= bounds[i].boxMax.y && bounds[i].boxMin.z <= bounds[i].boxMax.z))
      throw std::invalid_argument(m_name + "::AddGeom_AABB: box " + std::to_string(i) + " is empty or not finite");
  }
  mesh = Mesh{};
  mesh.boxes = true;
  mesh.tree = boxNumber > 0 ? m_builder(bounds.data(), int(boxNumber)) : BVHTree{};
  if (boxNumber > 0)
  {
    mesh.wide = CollapseTree(mesh.tree, [&](uint32_t k) { return bounds[mesh.tree.primIndices[k]]; });
    GroupBoxes(mesh.wide, bounds, mesh.tree.primIndices, customPrimCount > 0 ? uint32_t(boxNumber / customPrimCount) : 1u, mesh.boxGroups);
  }
  ClearDeviceData();
}

uint32_t BVHScene::AddGeom_AABB(uint32_t, const CRT_AABB* boxMinMaxF8, size_t boxNumber, uint32_t, void**, size_t customPrimCount)
{
  Mesh mesh;
  SetBoxes(mesh, boxMinMaxF8, boxNumber, customPrimCount);
  m_meshes.push_back(std::move(mesh));
  return uint32_t(m_meshes.size() - 1) | CRT_GEOM_MASK_AABB_BIT;
}

void BVHScene::UpdateGeom_AABB(uint32_t geomId, uint32_t, const CRT_AABB* boxMinMaxF8, size_t boxNumber, uint32_t, void**,
                               size_t customPrimCount)
{
  geomId &= CRT_GEOM_MASK_AABB_BIT_RM;
  if (geomId >= m_meshes.size() || !m_meshes[geomId].boxes || m_meshes[geomId].sdf)
    throw std::out_of_range(m_name + "::UpdateGeom_AABB: " + std::to_string(geomId) + " is no box geometry");
  SetBoxes(m_meshes[geomId], boxMinMaxF8, boxNumber, customPrimCount);
}

// ---- signed distance fields: bricks of voxels as box geometry ----

namespace {

BVHSdfBrick MakeBrick(float3 brickMin, float voxelSize, uint32_t firstValue, uint32_t voxels, uint32_t stride, uint32_t bytesPerValue,
                      uint32_t localId)
{
  BVHSdfBrick b;
  b.minAndVoxelSize = float4(brickMin.x, brickMin.y, brickMin.z, voxelSize);
  b.firstValue = firstValue;
  b.voxels = voxels;
  b.stride = stride;
  b.bytesPerValue = bytesPerValue;
  b.localId = localId;
  b.occupied[0] = b.occupied[1] = 0xFFFFFFFFu;  // every voxel, until Occupancy finds which
  b.unused = 0u;
  return b;
}

// A brick's occupancy (BVHSdfBrick::occupied), from the corner values `words` holds: the bits of
// the voxels whose corners allow the surface (for bricks of at most kSdfMaskedVoxels^3 voxels), and
// the box of those voxels, returned, which is the brick's box in the tree: a ray that misses it
// visits no voxel of the brick at all. (The whole brick's box when none is found, as a guard.)
CRT_AABB Occupancy(BVHSdfBrick& b, const std::vector<uint32_t>& words)
{
  const uint32_t n = b.voxels;
  const bool masked = n <= kSdfMaskedVoxels;
  if (masked)
    b.occupied[0] = b.occupied[1] = 0u;
  const float diagonal = 1.7320508f * b.minAndVoxelSize.w;  // as the traversal dequantises
  uint32_t lo[3] = {n, n, n}, hi[3] = {0u, 0u, 0u};
  for (uint32_t z = 0; z < n; ++z)
    for (uint32_t y = 0; y < n; ++y)
      for (uint32_t x = 0; x < n; ++x)
      {
        litesdf::VoxelValues values;
        for (uint32_t c = 0; c < 8; ++c)
        {
          const uint32_t at = b.firstValue + ((z + (c >> 2)) * b.stride + y + ((c >> 1) & 1u)) * b.stride + x + (c & 1u);
          values.v[c] = litesdf::DequantiseDistance(litesdf::UnpackValue(words, at, b.bytesPerValue), diagonal, b.bytesPerValue);
        }
        if (!litesdf::MayHoldSurface(values))
          continue;
        const uint32_t at[3] = {x, y, z}, bit = x + n * (y + n * z);
        for (int a = 0; a < 3; ++a)
        {
          lo[a] = std::min(lo[a], at[a]);
          hi[a] = std::max(hi[a], at[a] + 1u);
        }
        if (masked)
          b.occupied[bit / 32] |= 1u << (bit % 32);
      }
  if (lo[0] >= hi[0])
    lo[0] = lo[1] = lo[2] = 0u, hi[0] = hi[1] = hi[2] = n;
  const float4 m = b.minAndVoxelSize;
  CRT_AABB box;
  box.boxMin = float4(m.x + m.w * float(lo[0]), m.y + m.w * float(lo[1]), m.z + m.w * float(lo[2]), 0.0f);
  box.boxMax = float4(m.x + m.w * float(hi[0]), m.y + m.w * float(hi[1]), m.z + m.w * float(hi[2]), 0.0f);
  return box;
}

}  // namespace

uint32_t BVHScene::AddSdf(std::vector<BVHSdfBrick> bricks, std::vector<uint32_t> words)
{
  std::vector<CRT_AABB> boxes(bricks.size());
  for (size_t i = 0; i < bricks.size(); ++i)
    boxes[i] = Occupancy(bricks[i], words);
  Mesh mesh;
  SetBoxes(mesh, boxes.data(), boxes.size(), 0);
  mesh.sdf = true;
  mesh.sdfBricks = std::move(bricks);
  mesh.sdfWords = std::move(words);
  m_meshes.push_back(std::move(mesh));
  return uint32_t(m_meshes.size() - 1);
}

uint32_t BVHScene::AddGeom_SdfSVS(const litesdf::SdfSVS& svs, uint32_t)
{
  if (const std::string problem = litesdf::Problem(svs); !problem.empty())
    throw std::invalid_argument(m_name + "::AddGeom_SdfSVS: " + problem);
  std::vector<BVHSdfBrick> bricks(svs.VoxelCount());
  for (size_t i = 0; i < bricks.size(); ++i)  // a voxel's 8 values: a brick of one voxel, x + 2y + 4z
    bricks[i] = MakeBrick(svs.VoxelMin(i), svs.VoxelSize(), uint32_t(8 * i), 1, 2, svs.bytesPerValue, uint32_t(i));
  return AddSdf(std::move(bricks), svs.values);
}

uint32_t BVHScene::AddGeom_SdfSBS(const litesdf::SdfSBS& sbs, uint32_t)
{
  if (const std::string problem = litesdf::Problem(sbs); !problem.empty())
    throw std::invalid_argument(m_name + "::AddGeom_SdfSBS: " + problem);
  std::vector<BVHSdfBrick> bricks(sbs.BrickCount());
  const uint32_t valuesPerWord = 4 / sbs.bytesPerValue;
  for (size_t b = 0; b < bricks.size(); ++b)  // each brick's values from a word of its own
    bricks[b] = MakeBrick(sbs.BrickMin(b), sbs.VoxelSize(), uint32_t(b * sbs.WordsPerBrick() * valuesPerWord), sbs.brickSize,
                          sbs.brickSize + 1, sbs.bytesPerValue, uint32_t(b));
  return AddSdf(std::move(bricks), sbs.values);
}

uint32_t BVHScene::AddGeom_SdfGrid(const litesdf::SdfGrid& grid, uint32_t)
{
  if (const std::string problem = litesdf::Problem(grid); !problem.empty())
    throw std::invalid_argument(m_name + "::AddGeom_SdfGrid: " + problem);
  const uint32_t s = grid.samples;
  std::vector<uint32_t> words(grid.values.size());
  std::memcpy(words.data(), grid.values.data(), words.size() * sizeof(uint32_t));
  // Bricks of 8^3 cells (fewer for a small grid); the last along an axis moves back to end at the
  // grid's end, overlapping its neighbour. Kept when the surface may cross them.
  const uint32_t cells = s - 1, edge = std::min(cells, 8u);
  std::vector<uint32_t> starts;
  for (uint32_t c = 0; c < cells; c += edge)
    starts.push_back(std::min(c, cells - edge));
  std::vector<BVHSdfBrick> bricks;
  for (uint32_t z0 : starts)
    for (uint32_t y0 : starts)
      for (uint32_t x0 : starts)
      {
        float lo = std::numeric_limits<float>::infinity(), hi = -lo;
        for (uint32_t z = z0; z <= z0 + edge; ++z)
          for (uint32_t y = y0; y <= y0 + edge; ++y)
            for (uint32_t x = x0; x <= x0 + edge; ++x)
            {
              lo = std::min(lo, grid.Value(x, y, z));
              hi = std::max(hi, grid.Value(x, y, z));
            }
        if (!(lo <= 0.0f && hi > 0.0f))
          continue;  // wholly outside or wholly inside
        const float3 brickMin = grid.boxMin + grid.CellSize() * float3(float(x0), float(y0), float(z0));
        bricks.push_back(MakeBrick(brickMin, grid.CellSize(), (z0 * s + y0) * s + x0, edge, s, 4, 0));
      }
  return AddSdf(std::move(bricks), std::move(words));
}

uint32_t BVHScene::AddInstanceMotion(uint32_t geomId, const float4x4* matrices, uint32_t matrixNumber)
{
  if (matrixNumber == 0)
    throw std::invalid_argument(m_name + "::AddInstanceMotion: no matrices");
  for (uint32_t k = 1; k < matrixNumber; k++)
    litert_detail::ValidateInstanceMatrix((m_name + "::AddInstanceMotion").c_str(), matrices[k]);
  const uint32_t instId = AddInstance(geomId, matrices[0]);
  if (matrixNumber > 1)
    m_placed[instId].motion.assign(matrices, matrices + matrixNumber);
  return instId;
}

uint32_t BVHScene::AddInstance(uint32_t geomId, const float4x4& matrix)
{
  geomId &= CRT_GEOM_MASK_AABB_BIT_RM;  // box geometry's id may come with its bit
  if (geomId >= m_meshes.size())
    throw std::out_of_range(m_name + "::AddInstance: invalid geomId " + std::to_string(geomId));
  litert_detail::ValidateInstanceMatrix((m_name + "::AddInstance").c_str(), matrix);
  m_placed.push_back({geomId, matrix, LiteMath::inverse4x4(matrix)});
  ClearDeviceData();
  return uint32_t(m_placed.size() - 1);
}

void BVHScene::UpdateInstance(uint32_t instanceId, const float4x4& matrix)
{
  if (instanceId >= m_placed.size())
    throw std::out_of_range(m_name + "::UpdateInstance: invalid instanceId " + std::to_string(instanceId));
  litert_detail::ValidateInstanceMatrix((m_name + "::UpdateInstance").c_str(), matrix);
  m_placed[instanceId].toWorld = matrix;
  m_placed[instanceId].toObject = LiteMath::inverse4x4(matrix);
  m_placed[instanceId].motion.clear();
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
    // A moving instance is within the hull of its box at each time step: the matrices interpolate linearly.
    Box4f box;
    const std::vector<float4x4> still = {m_placed[i].toWorld};
    for (const float4x4& toWorld : m_placed[i].motion.empty() ? still : m_placed[i].motion)
      for (int corner = 0; corner < 8; ++corner)
      {
        const float3 lo = tree.nodes[0].boxMin, hi = tree.nodes[0].boxMax;
        const float3 p((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y, (corner & 4) ? hi.z : lo.z);
        const float3 w = TransformPoint(toWorld, p);
        box.include(float4(w.x, w.y, w.z, 0.0f));
      }
    boxes.push_back(box);
    ids.push_back(i);
  }
  if (boxes.empty())
    return;  // nothing to hit: the device data stays empty
  const BVHTree top = m_builder(boxes.data(), int(boxes.size()));

  // Device data: the top tree first, so its root is node 0, then each mesh that has triangles.
  // One instance a leaf: a ray then enters only the instances whose boxes it enters, not a leaf's
  // others with them (each an object-space ray to prepare and a mesh's root to test).
  const std::vector<BVH4Node> topNodes = CollapseTree(top, [&](uint32_t k) { return boxes[top.primIndices[k]]; }, 1u);
  size_t nodeCount = topNodes.size(), groupCount = 0;
  for (const Mesh& mesh : m_meshes)
  {
    nodeCount += mesh.wide.size();
    groupCount += mesh.groups.size();
  }
  ReserveOnHugePages(m_nodes, nodeCount);
  ReserveOnHugePages(m_triangles, groupCount);
  ReserveOnHugePages(m_primIds, 4 * groupCount);
  AppendTree(m_nodes, topNodes, 0);
  std::vector<uint32_t> meshRoot(m_meshes.size(), kNoId);
  for (uint32_t g = 0; g < m_meshes.size(); ++g)
  {
    const Mesh& mesh = m_meshes[g];
    if (mesh.wide.empty())
      continue;
    if (mesh.sdf)
    {
      // Its box lanes and bricks moved behind those of the fields before it.
      const uint32_t firstBrick = uint32_t(m_sdfBricks.size());
      meshRoot[g] = AppendTree(m_nodes, mesh.wide, uint32_t(m_boxes.size()));
      for (BVH4Node group : mesh.boxGroups)
      {
        for (int lane = 0; lane < 4; ++lane)
          if (group.child[lane] != kNoChild)
            group.child[lane] += firstBrick;
        m_boxes.push_back(group);
      }
      for (BVHSdfBrick brick : mesh.sdfBricks)
      {
        brick.firstValue += uint32_t(m_sdfWords.size()) * (4u / brick.bytesPerValue);
        m_sdfBricks.push_back(brick);
      }
      m_sdfWords.insert(m_sdfWords.end(), mesh.sdfWords.begin(), mesh.sdfWords.end());
      continue;
    }
    if (mesh.boxes)
    {
      meshRoot[g] = AppendTree(m_nodes, mesh.wide, uint32_t(m_boxes.size()));
      m_boxes.insert(m_boxes.end(), mesh.boxGroups.begin(), mesh.boxGroups.end());
      continue;
    }
    meshRoot[g] = AppendTree(m_nodes, mesh.wide, uint32_t(m_triangles.size()));
    m_triangles.insert(m_triangles.end(), mesh.groups.begin(), mesh.groups.end());
    m_primIds.insert(m_primIds.end(), mesh.groupPrims.begin(), mesh.groupPrims.end());
  }
  for (uint32_t k : top.primIndices)
  {
    const Instance& placed = m_placed[ids[k]];
    BVHInstance inst;
    inst.toObjectRow0 = placed.toObject.get_row(0);
    inst.toObjectRow1 = placed.toObject.get_row(1);
    inst.toObjectRow2 = placed.toObject.get_row(2);
    const bool boxes = m_meshes[placed.geomId].boxes, sdf = m_meshes[placed.geomId].sdf;
    inst.instId = ids[k];
    inst.geomId = boxes && !sdf ? placed.geomId | CRT_GEOM_MASK_AABB_BIT : placed.geomId;
    inst.root = meshRoot[placed.geomId];
    inst.flags = (IsIdentity(placed.toObject) && placed.motion.empty() ? kInstanceIdentity : 0u) | (boxes ? kInstanceBoxes : 0u) |
                 (sdf ? kInstanceSdf : 0u) | (placed.motion.empty() ? 0u : kInstanceMotion);
    m_sceneKinds |= (inst.flags & (kInstanceBoxes | kInstanceSdf | kInstanceMotion)) | (boxes ? 0u : kSceneTriangles) |
                    ((inst.flags & (kInstanceIdentity | kInstanceMotion)) == 0u ? kSceneTransformed : 0u);
    inst.motionFirst = uint32_t(m_motion.size());
    inst.motionSteps = uint32_t(placed.motion.size());
    inst.unused0 = inst.unused1 = 0u;
    for (const float4x4& step : placed.motion)
      for (int row = 0; row < 3; ++row)
        m_motion.push_back(step.get_row(row));
    m_instances.push_back(inst);
  }
}

bool BVHScene::ExportScene(CRT_SceneExport& out) const
{
  static_assert(sizeof(BVHTriangle) == 9 * sizeof(float), "a triangle is copied as 9 floats");
  out = CRT_SceneExport{};
  const bool onlyStillTriangles = std::none_of(m_meshes.begin(), m_meshes.end(), [](const Mesh& m) { return m.boxes; }) &&
                                  std::all_of(m_placed.begin(), m_placed.end(), [](const Instance& p) { return p.motion.empty(); });
  if (!onlyStillTriangles)
    return false;  // the export holds triangles placed still
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

// Watertight ray/triangle test (Woop, Benthin and Wald 2013), both sides, of the four triangles of
// m_triangles[group] at once. Returns the lanes hit within [tnear, tfar] as bits, with their distances t and
// Embree-style barycentrics (u weights corner 1, v corner 2).
// kx, ky and kz are the ray's axes (r.kx, r.ky, r.kz), passed apart so that packet traversal can pass
// the ones its gang shares: the corners are then one load for all lanes, not a gather.
uint32_t BVHScene::IntersectGroup(const BVHTraceRay& r, uint32_t group, int kx, int ky, int kz, float tfar, float4& t, float4& u,
                                  float4& v) const
{
  // The corners relative to the origin, sheared so that the ray runs along +z from (0, 0). Each
  // coordinate is read from m_triangles where it is used: a copy of the group would be a local
  // array, which GPU compilers index in scratch memory.
  const float ox = r.org[kx];
  const float oy = r.org[ky];
  const float oz = r.org[kz];
  const float4 az = m_triangles[group].coord[kz] - oz;
  const float4 bz = m_triangles[group].coord[3 + kz] - oz;
  const float4 cz = m_triangles[group].coord[6 + kz] - oz;
  const float4 ax = (m_triangles[group].coord[kx] - ox) - r.sx * az;
  const float4 ay = (m_triangles[group].coord[ky] - oy) - r.sy * az;
  const float4 bx = (m_triangles[group].coord[3 + kx] - ox) - r.sx * bz;
  const float4 by = (m_triangles[group].coord[3 + ky] - oy) - r.sy * bz;
  const float4 cx = (m_triangles[group].coord[6 + kx] - ox) - r.sx * cz;
  const float4 cy = (m_triangles[group].coord[6 + ky] - oy) - r.sy * cz;
  float4 eu = cx * by - cy * bx;
  float4 ev = ax * cy - ay * cx;
  float4 ew = bx * ay - by * ax;
  const float4 zero = float4(0.0f);
  if (lane_mask_le(min(min(abs(eu), abs(ev)), abs(ew)), zero) != 0u)
  {
    // A lane on an edge in float: decide exactly, so that neighbouring triangles agree. (Unfused
    // rounding never flips the sign of a product difference, only zeroes it: the other lanes keep
    // their signs.)
    eu = DifferenceOfProducts(cx, by, cy, bx);
    ev = DifferenceOfProducts(ax, cy, ay, cx);
    ew = DifferenceOfProducts(bx, ay, by, ax);
  }
  // Inside when the three edge functions share a sign (zeros count as either).
  uint32_t hits = lane_mask_le(zero, min(min(eu, ev), ew)) | lane_mask_le(max(max(eu, ev), ew), zero);
  const float4 det = eu + ev + ew;
  hits = hits & ~(lane_mask_le(det, zero) & lane_mask_le(zero, det));  // edge-on or degenerate
  t = (eu * (r.sz * az) + ev * (r.sz * bz) + ew * (r.sz * cz)) / det;
  hits = hits & lane_mask_le(float4(r.tnear), t) & lane_mask_le(t, float4(tfar));  // NaN (an empty lane) fails
  u = ev / det;
  v = ew / det;
  return hits;
}

// Triangle `lane` of group g, as IntersectGroup tests it among four: the same arithmetic on that lane,
// so the same hit, t, u and v. Packet traversal tests a leaf's triangles one at a time against its
// gang's rays (a triangle's nine corner coordinates are then one load each, and four at once would
// spill). IntersectGroup decides every lane exactly where one lane's edge function is zero; this sets
// `onEdge` where this triangle's is, and leaves the group's exact test to its caller.
bool BVHScene::IntersectTriangle(const BVHTraceRay& r, uint32_t group, int lane, int kx, int ky, int kz, float tfar, float& t, float& u,
                                 float& v, bool& onEdge) const
{
  const float3 a = float3(m_triangles[group].coord[kx][lane], m_triangles[group].coord[ky][lane], m_triangles[group].coord[kz][lane]);
  const float3 b = float3(m_triangles[group].coord[3 + kx][lane], m_triangles[group].coord[3 + ky][lane], m_triangles[group].coord[3 + kz][lane]);
  const float3 c = float3(m_triangles[group].coord[6 + kx][lane], m_triangles[group].coord[6 + ky][lane], m_triangles[group].coord[6 + kz][lane]);
  return IntersectCorners(r, kx, ky, kz, a, b, c, tfar, t, u, v, onEdge);
}

// The arithmetic of IntersectTriangle, of a triangle's corners a, b and c given along the ray's axes
// (x along kx, y along ky, z along kz), as the triangle's group stores them.
bool BVHScene::IntersectCorners(const BVHTraceRay& r, int kx, int ky, int kz, float3 a, float3 b, float3 c, float tfar, float& t, float& u,
                                float& v, bool& onEdge) const
{
  const float ox = r.org[kx];
  const float oy = r.org[ky];
  const float oz = r.org[kz];
  const float az = a.z - oz;
  const float bz = b.z - oz;
  const float cz = c.z - oz;
  const float ax = (a.x - ox) - r.sx * az;
  const float ay = (a.y - oy) - r.sy * az;
  const float bx = (b.x - ox) - r.sx * bz;
  const float by = (b.y - oy) - r.sy * bz;
  const float cx = (c.x - ox) - r.sx * cz;
  const float cy = (c.y - oy) - r.sy * cz;
  const float eu = cx * by - cy * bx;
  const float ev = ax * cy - ay * cx;
  const float ew = bx * ay - by * ax;
  onEdge = onEdge || std::min(std::min(std::fabs(eu), std::fabs(ev)), std::fabs(ew)) <= 0.0f;
  const float det = eu + ev + ew;
  t = (eu * (r.sz * az) + ev * (r.sz * bz) + ew * (r.sz * cz)) / det;
  u = ev / det;
  v = ew / det;
  const bool inside = 0.0f <= std::min(std::min(eu, ev), ew) || std::max(std::max(eu, ev), ew) <= 0.0f;
  return inside && !(det <= 0.0f && 0.0f <= det) && r.tnear <= t && t <= tfar;  // NaN (an empty lane) fails
}

// The four boxes of box geometry's m_boxes[group], as a node's lanes: a ray hits one where it enters
// it (at tnear from inside), or for a signed distance field where it meets the surface in the brick
// the lane holds. On a hit nearer than tfar: sets tfar and the hit's t, primId and coords.
bool BVHScene::IntersectBoxes(const BVHTraceRay& r, uint32_t group, bool sdf, float& tfar, CRT_Hit& hit) const
{
  float4 exits;
  const float4 entries = SlabEntries(r, m_boxes[group], tfar, exits);
  uint32_t hits = lane_mask_le(entries, exits);
  bool found = false;
  while (hits != 0u)
  {
    const int lane = __builtin_ctz(hits);
    hits = hits & (hits - 1u);
    if (entries[lane] > tfar)
      continue;  // behind a box of this group taken before it
    if ((m_sceneKinds & kInstanceSdf) != 0u && sdf)
    {
      found = IntersectSdfBrick(r, m_boxes[group].child[lane], entries[lane], exits[lane], tfar, hit) || found;
      continue;
    }
    found = true;
    tfar = entries[lane];
    hit.t = entries[lane];
    hit.primId = m_boxes[group].child[lane];
    hit.coords[0] = 0.0f;
    hit.coords[1] = 0.0f;
  }
  return found;
}

// Value number `at` of m_sdfWords as stored, 1 or 2 bytes of it: its quantised code. A word holds 4
// or 2 codes: shifts and masks find it (a division by the count cost 8 integer divisions a voxel).
inline uint32_t BVHScene::SdfCode(uint32_t at, uint32_t bytes) const
{
  const uint32_t shift = bytes == 1u ? 2u : 1u;  // log2 of the codes a word holds
  const uint32_t maxCode = bytes == 1u ? 255u : 65535u;
  return (m_sdfWords[at >> shift] >> ((at & ((1u << shift) - 1u)) * 8u * bytes)) & maxCode;
}

// The ray's span [tEnter, tExit] in brick m_sdfBricks[brick]: its voxels in order along the ray
// (Amanatides and Woo), those whose corners allow the surface intersected (litesdf's
// IntersectVoxelSpan), up to the first hit. On a hit nearer than tfar: sets tfar and the hit's t,
// primId and normal (coords[0..2]). Voxels that cannot hold the surface are skipped as cheaply as
// can be: by their occupancy bit, else by their lowest code, before any value is dequantised. The
// span comes from the brick's box in the tree, the box of the voxels that may hold the surface
// (Occupancy), so a ray walks none of the others at a brick's sides. (On the bunny's 128^3 SBS,
// SdfRender_CPU rose from 7.5 to 10.6 Mrays/s with the skips and SdfCode, and to 13.6-14.1 with the
// tight boxes.)
bool BVHScene::IntersectSdfBrick(const BVHTraceRay& r, uint32_t brick, float tEnter, float tExit, float& tfar, CRT_Hit& hit) const
{
  const float size = m_sdfBricks[brick].minAndVoxelSize.w;
  const float3 brickMin = to_float3(m_sdfBricks[brick].minAndVoxelSize);
  const int n = int(m_sdfBricks[brick].voxels);
  const uint32_t stride = m_sdfBricks[brick].stride;
  const uint32_t plane = stride * stride;
  const uint32_t firstValue = m_sdfBricks[brick].firstValue;
  const uint32_t bytes = m_sdfBricks[brick].bytesPerValue;
  const uint32_t occupiedLow = m_sdfBricks[brick].occupied[0];
  const uint32_t occupiedHigh = m_sdfBricks[brick].occupied[1];
  const float diagonal = 1.7320508f * size;  // sqrt(3) voxel edges: what quantised values span
  const float t1 = std::min(tExit, tfar);
  const float3 entry = (r.org + tEnter * r.dir - brickMin) / size;
  int cell[3];
  int step[3];
  float tNext[3];
  float tDelta[3];
  for (int a = 0; a < 3; ++a)
  {
    cell[a] = clamp(int(std::floor(entry[a])), 0, n - 1);
    step[a] = r.dir[a] > 0.0f ? 1 : -1;
    const float boundary = brickMin[a] + size * float(cell[a] + (r.dir[a] > 0.0f ? 1 : 0));
    tNext[a] = r.invDir[a] != 0.0f ? (boundary - r.org[a]) * r.invDir[a] : std::numeric_limits<float>::max();
    tDelta[a] = r.invDir[a] != 0.0f ? size * std::fabs(r.invDir[a]) : std::numeric_limits<float>::max();
  }
  float tVoxel = tEnter;
  while (true)
  {
    const int a = tNext[0] < tNext[1] ? (tNext[0] < tNext[2] ? 0 : 2) : (tNext[1] < tNext[2] ? 1 : 2);
    const uint32_t first = firstValue + (uint32_t(cell[2]) * stride + uint32_t(cell[1])) * stride + uint32_t(cell[0]);
    // A small brick's occupancy bit says whether some corner is at or inside the surface, before
    // any corner is read (MayHoldSurface, precomputed).
    const uint32_t bit = uint32_t(cell[0] + n * (cell[1] + n * cell[2]));
    const uint32_t occupied = n > int(kSdfMaskedVoxels) ? 1u : ((bit < 32u ? occupiedLow : occupiedHigh) >> (bit % 32u)) & 1u;
    litesdf::VoxelValues values;
    bool mayHoldSurface = false;
    if (occupied != 0u && bytes == 4u)
    {
      for (uint32_t c = 0u; c < 8u; ++c)
        values.v[c] = as_float(m_sdfWords[first + (c & 1u) + ((c >> 1u) & 1u) * stride + (c >> 2u) * plane]);
      mayHoldSurface = litesdf::MayHoldSurface(values);
    }
    else if (occupied != 0u)
    {
      // Quantised (litesdf's DequantiseDistance): a corner is at or inside the surface exactly when
      // 2 code <= maxCode, so the lowest code decides before any code becomes a distance.
      const uint32_t maxCode = bytes == 1u ? 255u : 65535u;
      uint32_t codes[8];
      uint32_t lowest = maxCode;
      for (uint32_t c = 0u; c < 8u; ++c)
      {
        codes[c] = SdfCode(first + (c & 1u) + ((c >> 1u) & 1u) * stride + (c >> 2u) * plane, bytes);
        lowest = std::min(lowest, codes[c]);
      }
      mayHoldSurface = 2u * lowest <= maxCode;
      if (mayHoldSurface)
        for (uint32_t c = 0u; c < 8u; ++c)
          values.v[c] = (float(codes[c]) / float(maxCode) * 2.0f - 1.0f) * diagonal;
    }
    if (mayHoldSurface)
    {
      const float3 voxelMin = brickMin + size * float3(float(cell[0]), float(cell[1]), float(cell[2]));
      const litesdf::SdfHit h = litesdf::IntersectVoxelSpan(values, voxelMin, size, r.org, r.dir, tVoxel, std::min(tNext[a], t1),
                                                            kSdfNewtonIterations);
      if (h.t >= 0.0f)
      {
        tfar = h.t;
        hit.t = h.t;
        hit.primId = m_sdfBricks[brick].localId;
        hit.coords[0] = h.normal.x;
        hit.coords[1] = h.normal.y;
        hit.coords[2] = h.normal.z;
        return true;
      }
    }
    if (!(tNext[a] <= t1))
      return false;  // left the brick, or reached tfar
    cell[a] = cell[a] + step[a];
    if (cell[a] < 0 || cell[a] >= n)
      return false;
    tVoxel = tNext[a];
    tNext[a] = tNext[a] + tDelta[a];
  }
}

// Visits the leaves of the mesh tree at `root` that the ray may reach, nearest box first, and
// tests their triangles (or boxes). On a hit nearer than tfar: sets tfar and the hit's t, primId and
// barycentrics, and returns true (at the first hit when anyHit).
bool BVHScene::TraceMesh(const BVHTraceRay& ray, uint32_t root, uint32_t leaves, bool anyHit, float& tfar, CRT_Hit& hit) const
{
  // The rays of a SIMD gang (ISPC's lanes) in one mesh of triangles: together, whether they share
  // their axes (a camera's, shadow rays to one light) or not (bounces, ambient occlusion: one lane a
  // ray, gathering its own nodes, had run at a quarter to a third of the scalar loop's speed with
  // avx2 on an AMD EPYC, Zen 4). Boxes and fields, and a gang of one, walk alone.
  // With every lane on (a full gang, no lane ended before), ISPC compiles the walk with its mask
  // known, and keeps its structs in registers (Gang.h's AllLanesOn): 1.4x the walk's speed with
  // AVX2 on an AMD EPYC, Zen 4 (bunny).
  if (crossrt::GangSize() > 1 && crossrt::AllLanes(leaves == 0u && root == crossrt::FirstLane(root)))
  {
    bool together = false;  // (a return inside the AllLanesOn branch is refused: ISPC's unmasked cannot return)
    if (crossrt::AllLanesOn())
      together = TraceMeshTogether(ray, root, anyHit, tfar, hit);
    else
      together = TraceMeshTogether(ray, root, anyHit, tfar, hit);
    return together;
  }
  uint32_t stack[kStackSize];    // node indices and leaf references
  float stackEntry[kStackSize];  // their entry distances, to skip those beyond a hit found since
  int top = 0;
  uint32_t node = root;
  bool found = false;
  while (true)
  {
    // Down the inner nodes to a leaf, the nearest lane entered first; the other lanes entered wait on the
    // stack, the farthest lowest. A node with no lane entered ends the descent with kNoChild. (Rays that
    // run side by side in SIMD lanes, on ISPC and GPUs, so reach their leaves, and the stack, together.)
    while ((node & kLeafFlag) == 0)
    {
      float4 entries;
      uint4 children;
      const int entered = EnteredLanes(ray, m_nodes[node], Reach(tfar), entries, children);
      if (entered == 0)
      {
        node = kNoChild;
        break;
      }
      for (int lane = entered - 1; lane > 0; --lane)
      {
        stack[top] = children[lane];
        stackEntry[top] = entries[lane];
        top = top + 1;
      }
      node = children[0];
    }
    if (node != kNoChild)
    {
      const uint32_t first = (node & ~kLeafFlag) >> 3;
      const uint32_t last = first + (node & 7u);
      for (uint32_t g = first; g <= last; ++g)
      {
        // Boxes or triangles, as if and else: rays in SIMD lanes that all took one branch skip the
        // other (after a `continue`, ISPC's SSE4 code read triangles for lanes that had left). A
        // kind the scene does not hold is no branch at all in a shader specialised to it.
        if ((m_sceneKinds & kInstanceBoxes) != 0u && (leaves & kInstanceBoxes) != 0u)
        {
          if (IntersectBoxes(ray, g, (leaves & kInstanceSdf) != 0u, tfar, hit))
          {
            found = true;
            if (anyHit)
              return true;
          }
        }
        else if ((m_sceneKinds & kSceneTriangles) != 0u)
        {
          float4 t;
          float4 u;
          float4 v;
          const uint32_t hits = IntersectGroup(ray, g, ray.kx, ray.ky, ray.kz, tfar, t, u, v);
          if (TakeNearestHit(g, hits, t, u, v, anyHit, tfar, hit))
          {
            found = true;
            if (anyHit)
              return true;
          }
        }
      }
    }
    // Pop the next subtree that may still hold something nearer than tfar.
    do
    {
      if (top == 0)
        return found;
      top = top - 1;
    } while (stackEntry[top] > Reach(tfar));
    node = stack[top];
  }
}

// Takes what IntersectGroup found in group g: a hit nearer than tfar, or as near with a lower primId, so
// that the order in which a walk visits the groups never changes the answer (packet traversal visits
// them in another order than a ray alone). Sets tfar and the hit's t, primId and barycentrics, and
// returns whether it took one (the first when anyHit).
bool BVHScene::TakeNearestHit(uint32_t g, uint32_t hits, const float4& t, const float4& u, const float4& v, bool anyHit, float& tfar,
                              CRT_Hit& hit) const
{
  bool taken = false;
  while (hits != 0u)
  {
    const int lane = __builtin_ctz(hits);
    hits = hits & (hits - 1u);
    const uint32_t primId = m_primIds[4 * g + lane];
    if (t[lane] > tfar || (t[lane] == tfar && primId >= hit.primId))
      continue;  // behind a hit taken before it
    taken = true;
    tfar = t[lane];
    hit.t = t[lane];
    hit.primId = primId;
    hit.coords[0] = u[lane];
    hit.coords[1] = v[lane];
    if (anyHit)
      return true;
  }
  return taken;
}

// Packet traversal (Wald, Slusallek, Benthin and Wagner 2001; Embree's rtcIntersect16 walks so): the
// rays of a gang that share a root and their axes walk the tree together. The node, the stack and the
// order of descent are the gang's (CRT_UNIFORM, Gang.h): a node is loaded once and tested against
// every ray, the lanes some ray enters are taken nearest first by the least entry of any ray, and
// each ray keeps its own entry into every subtree on the stack and takes part in a subtree only while
// that entry is within its tfar. Each ray gets the hit TraceMesh would give it alone: the triangles
// it can reach are all tested, and TakeNearestHit's answer does not depend on their order.
bool BVHScene::TraceMeshTogether(const BVHTraceRay& ray, uint32_t root, bool anyHit, float& tfar, CRT_Hit& hit) const
{
  CRT_UNIFORM uint32_t stack[kStackSize];
  float stackEntry[kStackSize];  // this ray's entry into each subtree on the stack, kNotEntered if it does not enter it
  CRT_UNIFORM int top = 0;
  CRT_UNIFORM uint32_t node = crossrt::FirstLane(root);
  // Where the rays share their axes (a camera's, shadow rays to one light), a triangle's corners are
  // read at them, one load for the gang; other rays (bounces, ambient occlusion) read each its own.
  CRT_UNIFORM const bool sameAxes = crossrt::AllLanes(ray.kx == crossrt::FirstLane(ray.kx) && ray.kz == crossrt::FirstLane(ray.kz));
  CRT_UNIFORM const int kx = crossrt::FirstLane(ray.kx);
  CRT_UNIFORM const int ky = crossrt::FirstLane(ray.ky);
  CRT_UNIFORM const int kz = crossrt::FirstLane(ray.kz);
  float entry = ray.tnear;  // this ray's entry into `node`: it takes part while entry <= tfar
  bool found = false;
  // Where every ray of the gang runs the same way along each axis (a camera's rays mostly do), each
  // box's near and far planes are the same for all of them: chosen once, not per ray, with
  // SlabEntry's arithmetic (SlabEntryFacing), so with its entries and exits. With avx2 on an AMD EPYC
  // (Zen 4), the teapot traced 5-7% faster so, the bunny and the 871k dragon 0-3%; in the walk of a
  // few rays (TraceMeshQuads), where each lane still loads its own box, it made no difference.
  CRT_UNIFORM const bool negX = crossrt::AllLanes(ray.invDir.x < 0.0f);
  CRT_UNIFORM const bool negY = crossrt::AllLanes(ray.invDir.y < 0.0f);
  CRT_UNIFORM const bool negZ = crossrt::AllLanes(ray.invDir.z < 0.0f);
  CRT_UNIFORM const bool facing = !crossrt::AnyLane(ray.anyZeroAxis) && (negX || crossrt::AllLanes(!(ray.invDir.x < 0.0f))) &&
                                  (negY || crossrt::AllLanes(!(ray.invDir.y < 0.0f))) && (negZ || crossrt::AllLanes(!(ray.invDir.z < 0.0f)));
  while (true)
  {
    // Where half the gang's rays or fewer are left in the subtree (deep in the tree, where the rays of
    // a tile part ways), they walk it a few at a time, a quad of lanes per ray across a node's four
    // boxes (TraceMeshQuads; Embree's switch to rays alone): testing each box against the whole gang
    // would leave most of its lanes idle there. Measured on an AMD EPYC (Zen 4), against the walk
    // together throughout: the 871k-triangle dragon 10% faster with avx2 and 15-20% with avx512skx,
    // the smaller meshes within 3%. Switching at 2, 3 or 4 rays left was the same with avx2; with
    // avx512skx at 8 beat 4 and 2 on that dragon. With sse4 this is the walk of one ray at a time
    // across the four lanes, which had paid there on six meshes of seven.
    CRT_UNIFORM uint32_t alone = crossrt::LaneBits(entry <= Reach(tfar) && !(anyHit && found));
    if (crossrt::GangSize() >= 4 && crossrt::AllLanesOn() && __builtin_popcount(alone) <= crossrt::GangSize() / 2)
    {
      while (alone != 0u)
      {
        // The next GangSize() / 4 of them, a quad each.
        CRT_UNIFORM uint32_t some = 0u;
        for (int q = 0; q < crossrt::GangSize() / 4; ++q)
          some = some | (alone & ~some & (0u - (alone & ~some)));
        alone = alone & ~some;
        found = TraceMeshQuads(ray, some, node, anyHit, tfar, hit) || found;
      }
      node = kNoChild;  // on to the stack
    }
    while ((node & kLeafFlag) == 0)
    {
      // The node's four boxes first, one at a time, each against every ray, with no branch between
      // them (`facing` is the same throughout the walk): which boxes a gang enters is data, and a
      // mispredicted branch after each box had the AVX2 walk wait there (about 11% of its samples;
      // on an AMD EPYC the 871k-triangle dragon traced 12% faster so with avx2, 7% with avx512skx).
      // Then, of the lanes some ray enters, the gang goes on into the one some ray enters before it
      // enters the others so far (Embree's order: no reduction over the lanes), and the others wait
      // on the stack.
      const bool active = entry <= Reach(tfar) && !(anyHit && found);  // an any-hit ray that found one is done
      float childEntry[4];  // this ray's entry into each lane's box, kNotEntered where it does not enter it
      CRT_UNIFORM uint32_t entered = 0u;  // the lanes some ray enters
      for (int lane = 0; lane < 4; ++lane)
      {
        float exit = 0.0f;
        float boxEntry = 0.0f;
        if (facing)
        {
          CRT_UNIFORM const float nearX = negX ? m_nodes[node].maxX[lane] : m_nodes[node].minX[lane];
          CRT_UNIFORM const float nearY = negY ? m_nodes[node].maxY[lane] : m_nodes[node].minY[lane];
          CRT_UNIFORM const float nearZ = negZ ? m_nodes[node].maxZ[lane] : m_nodes[node].minZ[lane];
          CRT_UNIFORM const float farX = negX ? m_nodes[node].minX[lane] : m_nodes[node].maxX[lane];
          CRT_UNIFORM const float farY = negY ? m_nodes[node].minY[lane] : m_nodes[node].maxY[lane];
          CRT_UNIFORM const float farZ = negZ ? m_nodes[node].minZ[lane] : m_nodes[node].maxZ[lane];
          boxEntry = SlabEntryFacing(ray, float3(nearX, nearY, nearZ), float3(farX, farY, farZ), Reach(tfar), exit);
        }
        else
        {
          const float3 lo = float3(m_nodes[node].minX[lane], m_nodes[node].minY[lane], m_nodes[node].minZ[lane]);
          const float3 hi = float3(m_nodes[node].maxX[lane], m_nodes[node].maxY[lane], m_nodes[node].maxZ[lane]);
          boxEntry = SlabEntry(ray, lo, hi, Reach(tfar), exit);
        }
        const bool enters = active && boxEntry <= exit;
        childEntry[lane] = enters ? boxEntry : kNotEntered;
        entered = entered | (crossrt::AnyLane(enters) ? 1u << uint32_t(lane) : 0u);
      }
      CRT_UNIFORM uint32_t next = kNoChild;
      float nextEntry = kNotEntered;
      for (int lane = 0; lane < 4; ++lane)
      {
        if ((entered & (1u << uint32_t(lane))) == 0u)
          continue;
        if (next == kNoChild)
        {
          next = m_nodes[node].child[lane];
          nextEntry = childEntry[lane];
        }
        else if (crossrt::AnyLane(childEntry[lane] < nextEntry))
        {
          stack[top] = next;
          stackEntry[top] = nextEntry;
          top = top + 1;
          next = m_nodes[node].child[lane];
          nextEntry = childEntry[lane];
        }
        else
        {
          stack[top] = m_nodes[node].child[lane];
          stackEntry[top] = childEntry[lane];
          top = top + 1;
        }
      }
      node = next;
      entry = nextEntry;
      if (next == kNoChild)
        break;
    }
    // The leaf, for the rays still in it. The gang tests its triangles together, whichever rays
    // are in it, and the others take no hit (hits 0): a branch that differs between lanes would
    // make each write of t, u and v below a masked store to memory on ISPC.
    if (node != kNoChild && crossrt::AnyLane(entry <= Reach(tfar)))
    {
      const bool inLeaf = entry <= Reach(tfar) && !(anyHit && found);
      CRT_UNIFORM const uint32_t first = (node & ~kLeafFlag) >> 3;
      CRT_UNIFORM const uint32_t last = first + (node & 7u);
      for (uint32_t g = first; g <= last; ++g)
      {
        // The group's triangles one at a time; where a ray meets one on an edge (rare), the whole
        // group again as a ray alone tests it, so that every ray gets the same t, u and v.
        float4 t;
        float4 u;
        float4 v;
        uint32_t hits = 0u;
        bool onEdge = false;
        for (int lane = 0; lane < 4; ++lane)
        {
          float tl = 0.0f;
          float ul = 0.0f;
          float vl = 0.0f;
          bool hitsIt = false;
          if (sameAxes)
            hitsIt = IntersectTriangle(ray, g, lane, kx, ky, kz, tfar, tl, ul, vl, onEdge);
          else
          {
            // The nine coordinates, each one load for the gang, and each ray's picked with selects (its
            // own axes would be nine gathers: half the walk's time in a path tracer's bounces).
            const float3 a = AlongAxes(float3(m_triangles[g].coord[0][lane], m_triangles[g].coord[1][lane], m_triangles[g].coord[2][lane]),
                                       ray.kx, ray.ky, ray.kz);
            const float3 b = AlongAxes(float3(m_triangles[g].coord[3][lane], m_triangles[g].coord[4][lane], m_triangles[g].coord[5][lane]),
                                       ray.kx, ray.ky, ray.kz);
            const float3 c = AlongAxes(float3(m_triangles[g].coord[6][lane], m_triangles[g].coord[7][lane], m_triangles[g].coord[8][lane]),
                                       ray.kx, ray.ky, ray.kz);
            hitsIt = IntersectCorners(ray, ray.kx, ray.ky, ray.kz, a, b, c, tfar, tl, ul, vl, onEdge);
          }
          hits = hitsIt ? hits | (1u << uint32_t(lane)) : hits;
          t[lane] = tl;
          u[lane] = ul;
          v[lane] = vl;
        }
        if (crossrt::AnyLane(inLeaf && onEdge))
          hits = IntersectGroup(ray, g, ray.kx, ray.ky, ray.kz, tfar, t, u, v);
        hits = inLeaf ? hits : 0u;
        found = TakeNearestHit(g, hits, t, u, v, anyHit, tfar, hit) || found;
      }
      // Any-hit rays that found one are done; the gang returns when all are, on a condition the gang
      // shares. (A return of some lanes only would switch them off for the rest of the walk: ISPC's
      // masked stores again.)
      if (crossrt::AllLanes(anyHit && found))
        return true;
    }
    // Pop the next subtree that some ray may still find something nearer in.
    do
    {
      if (top == 0)
        return found;
      top = top - 1;
    } while (!crossrt::AnyLane(stackEntry[top] <= Reach(tfar)));
    node = stack[top];
    entry = stackEntry[top];
  }
}

// A few rays of the gang, those in the lanes `rays` (bits; GangSize() / 4 of them at most), walk the
// subtree at `root` together, a quad of four lanes per ray: each lane of a quad tests a box of each
// node and a triangle of each leaf group for its quad's ray (SIMD across a node, as Embree's walk of
// one ray), and the quads share the node and the stack (a packet of a few rays). Gangs of 8 and 16
// lanes walk so where few of their rays are left in a subtree, deep in the tree, where
// TraceMeshTogether would test each box with most of its lanes idle. The arithmetic is TraceMesh's
// (SlabEntry, IntersectCorners as IntersectTriangle calls it and, where a ray meets a triangle on an
// edge, IntersectGroup), and so is each ray's hit. Runs with every lane of the gang on (its caller
// tests AllLanesOn()): a lane works for another lane's ray. Updates those rays' tfar and hit in their
// own lanes, and returns true in the lanes of those that found one.
bool BVHScene::TraceMeshQuads(const BVHTraceRay& gangRay, uint32_t rays, uint32_t root, bool anyHit, float& tfar, CRT_Hit& hit) const
{
  CRT_UNIFORM const uint32_t raySet = crossrt::FirstLane(rays);
  if (raySet == 0u)
    return false;
  // This lane's place in its quad (the box, or the triangle, it tests), and the lane whose ray its quad
  // works for: quad q takes the q-th ray of the set.
  const int quad = crossrt::LaneIndex() / 4;
  const int box = crossrt::LaneIndex() % 4;
  int from = 0;
  bool inQuad = false;  // the quad has a ray
  CRT_UNIFORM uint32_t left = raySet;
  for (int q = 0; q < crossrt::GangSize() / 4; ++q)
  {
    if (left == 0u)
      break;
    CRT_UNIFORM const int lane = __builtin_ctz(left);
    left = left & (left - 1u);
    from = quad == q ? lane : from;
    inQuad = inQuad || quad == q;
  }
  const BVHTraceRay ray = RayFromLane(gangRay, from);
  // The axes, where the gang's rays share them (TraceMeshTogether): a triangle's corners along them
  // are then three loads of the group. Otherwise each quad reads all nine and picks its ray's.
  CRT_UNIFORM const bool sameAxes = crossrt::AllLanes(gangRay.kx == crossrt::FirstLane(gangRay.kx) && gangRay.kz == crossrt::FirstLane(gangRay.kz));
  CRT_UNIFORM const int kx = crossrt::FirstLane(gangRay.kx);
  CRT_UNIFORM const int ky = crossrt::FirstLane(gangRay.ky);
  CRT_UNIFORM const int kz = crossrt::FirstLane(gangRay.kz);
  const bool firstHit = crossrt::FromLane(anyHit, from);
  // The quad's ray's tfar and hit, in each lane of the quad.
  float rayTfar = crossrt::FromLane(tfar, from);
  float hitT = crossrt::FromLane(hit.t, from);
  uint32_t hitPrimId = crossrt::FromLane(hit.primId, from);
  float hitU = crossrt::FromLane(hit.coords[0], from);
  float hitV = crossrt::FromLane(hit.coords[1], from);
  bool found = false;
  CRT_UNIFORM uint32_t stack[kStackSize];
  float stackEntry[kStackSize];  // the quad's ray's entry into each subtree on the stack, kNotEntered if it does not enter it
  CRT_UNIFORM int top = 0;
  CRT_UNIFORM uint32_t node = crossrt::FirstLane(root);
  float entry = ray.tnear;  // the quad's ray's entry into `node`
  while (true)
  {
    while ((node & kLeafFlag) == 0)
    {
      // Box `box` of the node, for the quad's ray; then the boxes some ray enters, as TraceMeshTogether
      // takes them: on into the one some ray enters before the others taken so far, the others on the stack.
      const bool active = inQuad && entry <= Reach(rayTfar) && !(firstHit && found);
      float exit = 0.0f;
      const float3 lo = float3(crossrt::LaneOfQuad(m_nodes[node].minX), crossrt::LaneOfQuad(m_nodes[node].minY),
                               crossrt::LaneOfQuad(m_nodes[node].minZ));
      const float3 hi = float3(crossrt::LaneOfQuad(m_nodes[node].maxX), crossrt::LaneOfQuad(m_nodes[node].maxY),
                               crossrt::LaneOfQuad(m_nodes[node].maxZ));
      const float boxEntry = SlabEntry(ray, lo, hi, Reach(rayTfar), exit);
      const bool enters = active && boxEntry <= exit;
      const float childEntry = enters ? boxEntry : kNotEntered;
      CRT_UNIFORM const uint32_t bits = crossrt::LaneBits(enters);
      CRT_UNIFORM const uint32_t entered = (bits | bits >> 4u | bits >> 8u | bits >> 12u) & 15u;
      if (entered == 0u)
      {
        node = kNoChild;
        break;
      }
      CRT_UNIFORM uint32_t next = kNoChild;
      float nextEntry = kNotEntered;
      for (int b = 0; b < 4; ++b)
      {
        if ((entered & (1u << uint32_t(b))) == 0u)
          continue;
        const float boxEntryOfRay = crossrt::FromLane(childEntry, crossrt::LaneIndex() - box + b);  // the quad's ray's, into box b
        if (next == kNoChild)
        {
          next = m_nodes[node].child[b];
          nextEntry = boxEntryOfRay;
        }
        else if (crossrt::AnyLane(boxEntryOfRay < nextEntry))
        {
          stack[top] = next;
          stackEntry[top] = nextEntry;
          top = top + 1;
          next = m_nodes[node].child[b];
          nextEntry = boxEntryOfRay;
        }
        else
        {
          stack[top] = m_nodes[node].child[b];
          stackEntry[top] = boxEntryOfRay;
          top = top + 1;
        }
      }
      node = next;
      entry = nextEntry;
    }
    if (node != kNoChild)
    {
      CRT_UNIFORM const uint32_t first = (node & ~kLeafFlag) >> 3;
      CRT_UNIFORM const uint32_t last = first + (node & 7u);
      for (uint32_t g = first; g <= last; ++g)
      {
        // Triangle `box` of the group, for the quad's ray.
        const bool live = inQuad && entry <= Reach(rayTfar) && !(firstHit && found);
        float t = 0.0f;
        float u = 0.0f;
        float v = 0.0f;
        bool edge = false;
        bool hitsIt = false;
        if (sameAxes)
        {
          const float3 a = float3(crossrt::LaneOfQuad(m_triangles[g].coord[kx]), crossrt::LaneOfQuad(m_triangles[g].coord[ky]),
                                  crossrt::LaneOfQuad(m_triangles[g].coord[kz]));
          const float3 b = float3(crossrt::LaneOfQuad(m_triangles[g].coord[3 + kx]), crossrt::LaneOfQuad(m_triangles[g].coord[3 + ky]),
                                  crossrt::LaneOfQuad(m_triangles[g].coord[3 + kz]));
          const float3 c = float3(crossrt::LaneOfQuad(m_triangles[g].coord[6 + kx]), crossrt::LaneOfQuad(m_triangles[g].coord[6 + ky]),
                                  crossrt::LaneOfQuad(m_triangles[g].coord[6 + kz]));
          hitsIt = IntersectCorners(ray, kx, ky, kz, a, b, c, rayTfar, t, u, v, edge);
        }
        else
        {
          const float3 a = AlongAxes(float3(crossrt::LaneOfQuad(m_triangles[g].coord[0]), crossrt::LaneOfQuad(m_triangles[g].coord[1]),
                                            crossrt::LaneOfQuad(m_triangles[g].coord[2])),
                                     ray.kx, ray.ky, ray.kz);
          const float3 b = AlongAxes(float3(crossrt::LaneOfQuad(m_triangles[g].coord[3]), crossrt::LaneOfQuad(m_triangles[g].coord[4]),
                                            crossrt::LaneOfQuad(m_triangles[g].coord[5])),
                                     ray.kx, ray.ky, ray.kz);
          const float3 c = AlongAxes(float3(crossrt::LaneOfQuad(m_triangles[g].coord[6]), crossrt::LaneOfQuad(m_triangles[g].coord[7]),
                                            crossrt::LaneOfQuad(m_triangles[g].coord[8])),
                                     ray.kx, ray.ky, ray.kz);
          hitsIt = IntersectCorners(ray, ray.kx, ray.ky, ray.kz, a, b, c, rayTfar, t, u, v, edge);
        }
        CRT_UNIFORM const uint32_t edges = crossrt::LaneBits(live && edge);
        if (edges != 0u)
        {
          // A triangle on an edge in float: as TraceMesh tests it, in its group, exactly. IntersectGroup
          // then decides all four triangles of the group so (their t, u and v to the last bit), so every
          // lane of a quad where one is on an edge takes the group's answer, not its own.
          const bool exact = ((edges >> uint32_t(4 * quad)) & 15u) != 0u;
          float4 t4;
          float4 u4;
          float4 v4;
          const uint32_t groupHits = IntersectGroup(ray, g, ray.kx, ray.ky, ray.kz, rayTfar, t4, u4, v4);
          hitsIt = exact ? ((groupHits >> uint32_t(box)) & 1u) != 0u : hitsIt;
          t = exact ? t4[box] : t;
          u = exact ? u4[box] : u;
          v = exact ? v4[box] : v;
        }
        hitsIt = hitsIt && live;
        if (crossrt::AnyLane(hitsIt))
        {
          // The quad's nearest hit, or as near with a lower primId, in each of its lanes (lanes 1 and 2
          // apart swap theirs); taken where TakeNearestHit would take it.
          bool best = hitsIt;
          float bestT = t;
          uint32_t bestPrimId = m_primIds[4u * g + uint32_t(box)];
          float bestU = u;
          float bestV = v;
          for (int apart = 1; apart < 4; apart = apart * 2)
          {
            const int other = crossrt::LaneIndex() ^ apart;
            const bool otherBest = crossrt::FromLane(best, other);
            const float otherT = crossrt::FromLane(bestT, other);
            const uint32_t otherPrimId = crossrt::FromLane(bestPrimId, other);
            const float otherU = crossrt::FromLane(bestU, other);
            const float otherV = crossrt::FromLane(bestV, other);
            const bool takeOther = otherBest && (!best || otherT < bestT || (otherT == bestT && otherPrimId < bestPrimId));
            best = best || otherBest;
            bestT = takeOther ? otherT : bestT;
            bestPrimId = takeOther ? otherPrimId : bestPrimId;
            bestU = takeOther ? otherU : bestU;
            bestV = takeOther ? otherV : bestV;
          }
          const bool nearer = best && (bestT < rayTfar || (bestT == rayTfar && bestPrimId < hitPrimId));
          found = found || nearer;
          rayTfar = nearer ? bestT : rayTfar;
          hitT = nearer ? bestT : hitT;
          hitPrimId = nearer ? bestPrimId : hitPrimId;
          hitU = nearer ? bestU : hitU;
          hitV = nearer ? bestV : hitV;
        }
      }
      if (crossrt::AllLanes(!inQuad || (firstHit && found)))
        break;  // every any-hit ray found one (a condition the gang shares: the walk stays the gang's)
    }
    // Pop the next subtree that some ray may still find something nearer in.
    CRT_UNIFORM bool popped = false;
    while (top > 0 && !popped)
    {
      top = top - 1;
      popped = crossrt::AnyLane(inQuad && stackEntry[top] <= Reach(rayTfar) && !(firstHit && found));
    }
    if (!popped)
      break;
    node = stack[top];
    entry = stackEntry[top];
  }
  // Back into the rays' lanes: the ray of lane L is the quad's whose place among the rays is L's.
  const bool mine = ((raySet >> uint32_t(crossrt::LaneIndex())) & 1u) != 0u;
  const int source = mine ? 4 * __builtin_popcount(raySet & ((1u << uint32_t(crossrt::LaneIndex())) - 1u)) : 0;
  tfar = mine ? crossrt::FromLane(rayTfar, source) : tfar;
  hit.t = mine ? crossrt::FromLane(hitT, source) : hit.t;
  hit.primId = mine ? crossrt::FromLane(hitPrimId, source) : hit.primId;
  hit.coords[0] = mine ? crossrt::FromLane(hitU, source) : hit.coords[0];
  hit.coords[1] = mine ? crossrt::FromLane(hitV, source) : hit.coords[1];
  return mine && crossrt::FromLane(found, source);
}

// Traces instance m_instances[k] in object space (affine maps keep t: the object-space ray is not
// renormalized). On a hit nearer than tfar, sets the hit's ids too.
bool BVHScene::TraceInstance(uint32_t k, const BVHTraceRay& worldRay, float time, bool anyHit, float& tfar, CRT_Hit& hit) const
{
  const BVHInstance& inst = m_instances[k];
  const uint32_t leaves = inst.flags & (kInstanceBoxes | kInstanceSdf);
  // The ray in object space; one call of TraceMesh below, so that a shader holds one copy of the walk
  // (GLSL inlines every call). Branches on kinds the scene does not hold (m_sceneKinds) vanish from a
  // specialised shader.
  BVHTraceRay ray = worldRay;
  if ((m_sceneKinds & kInstanceMotion) != 0u && (inst.flags & kInstanceMotion) != 0u)
  {
    // Its object-to-world matrix at the ray's time, between the two steps around it, inverted.
    const float f = clamp(time, 0.0f, 1.0f) * float(inst.motionSteps - 1u);
    const uint32_t step = std::min(uint32_t(f), inst.motionSteps - 2u);
    const float w = f - float(step);
    const uint32_t at = inst.motionFirst + 3u * step;
    const float4 row0 = mix(m_motion[at], m_motion[at + 3u], w);
    const float4 row1 = mix(m_motion[at + 1u], m_motion[at + 4u], w);
    const float4 row2 = mix(m_motion[at + 2u], m_motion[at + 5u], w);
    const float3x3 toObject = inverse(make_float3x3_from_rows(to_float3(row0), to_float3(row1), to_float3(row2)));
    const float3 org = toObject * (worldRay.org - float3(row0.w, row1.w, row2.w));
    ray = Prepare(org, toObject * worldRay.dir, worldRay.tnear);
  }
  else if ((m_sceneKinds & kSceneTransformed) != 0u && (inst.flags & kInstanceIdentity) == 0u)
    ray = Prepare(ToObjectPoint(inst, worldRay.org), ToObjectVector(inst, worldRay.dir), worldRay.tnear);
  const bool found = TraceMesh(ray, inst.root, leaves, anyHit, tfar, hit);
  hit.instId = found ? inst.instId : hit.instId;  // selects: the same in SIMD lanes that differ
  hit.geomId = found ? inst.geomId : hit.geomId;
  return found;
}

// The top tree's leaves hold instances. This loop and TraceMesh's walk the stack alike; a shared
// step function would take the stack arrays as GLSL inout parameters, which copy them on every
// call.
bool BVHScene::Trace(float4 posAndNear, float4 dirAndFar, float time, bool anyHit, CRT_Hit& hit) const
{
  float tnear = 0.0f;
  float tfar = 0.0f;
  const bool valid = litert_detail::RayInterval(posAndNear, dirAndFar, tnear, tfar);
  if (m_nodes.size() == 0 || !crossrt::AnyLane(valid))
    return false;
  // A ray that is not valid beside valid ones in a gang walks with an interval that enters nothing
  // (tfar below tnear), rather than leaving: the lanes stay on together, and ISPC keeps its locals in
  // registers (a lane switched off makes every store to a local struct a masked store to memory).
  tfar = valid ? tfar : -1.0f;
  const BVHTraceRay worldRay = Prepare(to_float3(posAndNear), to_float3(dirAndFar), tnear);
  // A single instance in SIMD lanes: its mesh at once, outside the walk's loop below, whose
  // conditions differ between lanes as far as ISPC knows. So the lanes stay on together in the
  // packet walk, and ISPC keeps its structs in registers there. (A gang of one takes the loop.)
  if (crossrt::GangSize() > 1 && m_instances.size() == 1)
    return TraceInstance(0u, worldRay, time, anyHit, tfar, hit);
  // Several instances in SIMD lanes: the gang walks the top tree together, so that it enters each
  // instance's mesh from one root and walks that together too (TraceMesh). One lane a ray, each lane
  // gathering its own nodes and instances, had traced a path tracer's bounces at a third of the
  // scalar loop's speed with avx2 on an AMD EPYC (Zen 4).
  if (crossrt::GangSize() > 1 && m_instances.size() > 1)
  {
    bool together = false;  // (a return inside the AllLanesOn branch is refused: ISPC's unmasked cannot return)
    if (crossrt::AllLanesOn())
      together = TraceTogether(worldRay, time, anyHit, tfar, hit);
    else
      together = TraceTogether(worldRay, time, anyHit, tfar, hit);
    return together;
  }
  uint32_t stack[kStackSize];
  float stackEntry[kStackSize];
  int top = 0;
  // The root; for a single instance, a leaf holding it (no top tree to walk: its root tests the same
  // box), so that the loop below is the only call of TraceInstance and a shader holds one copy of it.
  uint32_t node = m_instances.size() == 1 ? kLeafFlag : 0u;
  bool found = false;
  while (true)
  {
    if ((node & kLeafFlag) != 0)
    {
      const uint32_t first = (node & ~kLeafFlag) >> 3;
      const uint32_t last = first + (node & 7u);
      for (uint32_t k = first; k <= last; ++k)
      {
        if (!TraceInstance(k, worldRay, time, anyHit, tfar, hit))
          continue;
        found = true;
        if (anyHit)
          return true;
      }
    }
    else
    {
      // Go on with the nearest lane entered; the others wait on the stack, the farthest lowest.
      float4 entries;
      uint4 children;
      const int entered = EnteredLanes(worldRay, m_nodes[node], Reach(tfar), entries, children);
      if (entered > 0)
      {
        for (int lane = entered - 1; lane > 0; --lane)
        {
          stack[top] = children[lane];
          stackEntry[top] = entries[lane];
          top = top + 1;
        }
        node = children[0];
        continue;
      }
    }
    do
    {
      if (top == 0)
        return found;
      top = top - 1;
    } while (stackEntry[top] > Reach(tfar));
    node = stack[top];
  }
}

// The top tree, walked by the rays of a gang together, as TraceMeshTogether walks a mesh's: the node,
// the stack and the order of descent are the gang's, and each ray keeps its own entry into each
// subtree on the stack. At a leaf the gang traces each instance in it for all its rays at once; a ray
// that is not in the leaf takes part with an interval that enters nothing (tfar -1), so the lanes stay
// on together and each instance's mesh is entered by the whole gang from its root. Each ray gets the
// hit Trace's walk gives it alone: every instance whose box it enters within its tfar is traced.
bool BVHScene::TraceTogether(const BVHTraceRay& ray, float time, bool anyHit, float& tfar, CRT_Hit& hit) const
{
  CRT_UNIFORM uint32_t stack[kStackSize];
  float stackEntry[kStackSize];  // this ray's entry into each subtree on the stack, kNotEntered if it does not enter it
  CRT_UNIFORM int top = 0;
  CRT_UNIFORM uint32_t node = 0u;
  float entry = ray.tnear;  // this ray's entry into `node`
  bool found = false;
  while (true)
  {
    while ((node & kLeafFlag) == 0u)
    {
      // The four boxes, each against every ray; then on into the lane some ray enters first, as
      // TraceMeshTogether goes, the others on the stack. (Written again rather than shared: a helper
      // could not take the gang's CRT_UNIFORM stack by reference, nor return `entered` as shared.)
      const bool active = entry <= Reach(tfar) && !(anyHit && found);
      float childEntry[4];
      CRT_UNIFORM uint32_t entered = 0u;
      for (int lane = 0; lane < 4; ++lane)
      {
        float exit = 0.0f;
        const float3 lo = float3(m_nodes[node].minX[lane], m_nodes[node].minY[lane], m_nodes[node].minZ[lane]);
        const float3 hi = float3(m_nodes[node].maxX[lane], m_nodes[node].maxY[lane], m_nodes[node].maxZ[lane]);
        const float boxEntry = SlabEntry(ray, lo, hi, Reach(tfar), exit);
        const bool enters = active && boxEntry <= exit;
        childEntry[lane] = enters ? boxEntry : kNotEntered;
        entered = entered | (crossrt::AnyLane(enters) ? 1u << uint32_t(lane) : 0u);
      }
      CRT_UNIFORM uint32_t next = kNoChild;
      float nextEntry = kNotEntered;
      for (int lane = 0; lane < 4; ++lane)
      {
        if ((entered & (1u << uint32_t(lane))) == 0u)
          continue;
        if (next == kNoChild)
        {
          next = m_nodes[node].child[lane];
          nextEntry = childEntry[lane];
        }
        else if (crossrt::AnyLane(childEntry[lane] < nextEntry))
        {
          stack[top] = next;
          stackEntry[top] = nextEntry;
          top = top + 1;
          next = m_nodes[node].child[lane];
          nextEntry = childEntry[lane];
        }
        else
        {
          stack[top] = m_nodes[node].child[lane];
          stackEntry[top] = childEntry[lane];
          top = top + 1;
        }
      }
      node = next;
      entry = nextEntry;
      if (next == kNoChild)
        break;
    }
    if (node != kNoChild && crossrt::AnyLane(entry <= Reach(tfar) && !(anyHit && found)))
    {
      CRT_UNIFORM const uint32_t first = (node & ~kLeafFlag) >> 3;
      CRT_UNIFORM const uint32_t last = first + (node & 7u);
      for (uint32_t k = first; k <= last; ++k)
      {
        const bool inLeaf = entry <= Reach(tfar) && !(anyHit && found);
        float leafTfar = inLeaf ? tfar : -1.0f;  // enters nothing: no hit is taken
        const bool foundHere = TraceInstance(k, ray, time, anyHit, leafTfar, hit);
        tfar = inLeaf ? leafTfar : tfar;
        found = found || (inLeaf && foundHere);
      }
      if (crossrt::AllLanes(anyHit && found))
        return true;
    }
    // Pop the next subtree that some ray may still find something nearer in.
    do
    {
      if (top == 0)
        return found;
      top = top - 1;
    } while (!crossrt::AnyLane(stackEntry[top] <= Reach(tfar) && !(anyHit && found)));
    node = stack[top];
    entry = stackEntry[top];
  }
}

CRT_Hit BVHScene::RayQuery_NearestHit(float4 posAndNear, float4 dirAndFar) { return NearestHit(posAndNear, dirAndFar, 0.0f); }

bool BVHScene::RayQuery_AnyHit(float4 posAndNear, float4 dirAndFar) { return AnyHit(posAndNear, dirAndFar, 0.0f); }

CRT_Hit BVHScene::RayQuery_NearestHitMotion(float4 posAndNear, float4 dirAndFar, float time) { return NearestHit(posAndNear, dirAndFar, time); }

bool BVHScene::RayQuery_AnyHitMotion(float4 posAndNear, float4 dirAndFar, float time) { return AnyHit(posAndNear, dirAndFar, time); }

CRT_Hit BVHScene::NearestHit(float4 posAndNear, float4 dirAndFar, float time) const
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
  Trace(posAndNear, dirAndFar, time, false, hit);
  return hit;
}

bool BVHScene::AnyHit(float4 posAndNear, float4 dirAndFar, float time) const
{
  CRT_Hit unused;
  unused.t = dirAndFar.w;
  unused.primId = kNoId;  // TakeNearestHit compares it
  return Trace(posAndNear, dirAndFar, time, true, unused);
}
