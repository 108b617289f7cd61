#include "SAHBuilder.h"

#include <algorithm>
#include <numeric>
#include <vector>

using LiteMath::Box4f;
using LiteMath::float3;

namespace {

constexpr int kBins = 32;
constexpr uint32_t kMaxDepth = 48;  // traversal stacks hold 64 entries

struct Bounds
{
  float3 lo = float3(1e30f), hi = float3(-1e30f);
  void Include(float3 pLo, float3 pHi) { lo = min(lo, pLo); hi = max(hi, pHi); }
  void Include(const Bounds& b) { Include(b.lo, b.hi); }
  float HalfArea() const
  {
    if (lo.x > hi.x) return 0.0f;
    const float3 e = hi - lo;
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
};

float Axis(float3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

}  // namespace

BVHTree BuildBinnedSAH(const Box4f* boxes, int count, int maxLeafSize)
{
  BVHTree tree;
  if (count <= 0)
    return tree;
  maxLeafSize = std::max(maxLeafSize, 1);
  std::vector<float3> centers(count);
  for (int i = 0; i < count; ++i)
    centers[i] = 0.5f * (to_float3(boxes[i].boxMin) + to_float3(boxes[i].boxMax));
  tree.primIndices.resize(count);
  std::iota(tree.primIndices.begin(), tree.primIndices.end(), 0u);
  tree.nodes.reserve(2 * size_t(count));
  tree.nodes.push_back({});

  struct Task { uint32_t node, first, count, depth; };
  std::vector<Task> tasks = {{0, 0, uint32_t(count), 0}};
  while (!tasks.empty())
  {
    const Task task = tasks.back();
    tasks.pop_back();
    uint32_t* prims = tree.primIndices.data() + task.first;
    Bounds box, centerBox;
    for (uint32_t k = 0; k < task.count; ++k)
    {
      box.Include(to_float3(boxes[prims[k]].boxMin), to_float3(boxes[prims[k]].boxMax));
      centerBox.Include(centers[prims[k]], centers[prims[k]]);
    }
    BVHNode& node = tree.nodes[task.node];
    node.boxMin = box.lo;
    node.boxMax = box.hi;
    node.left = kLeafFlag | task.first;
    node.right = task.count;

    const float3 extent = centerBox.hi - centerBox.lo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    const float axisMin = Axis(centerBox.lo, axis), axisExtent = Axis(extent, axis);
    if (task.count <= 1 || axisExtent <= 0.0f || task.depth >= kMaxDepth)
      continue;  // one primitive, centers that no plane separates, or deep enough: a leaf

    // Bin the centers, then sweep for the cheapest split: cost ~ area * primitives on each side.
    auto binOf = [&](uint32_t p) { return std::min(kBins - 1, int((Axis(centers[p], axis) - axisMin) * (kBins / axisExtent))); };
    Bounds bins[kBins];
    uint32_t binCount[kBins] = {};
    for (uint32_t k = 0; k < task.count; ++k)
    {
      const int b = binOf(prims[k]);
      bins[b].Include(to_float3(boxes[prims[k]].boxMin), to_float3(boxes[prims[k]].boxMax));
      binCount[b]++;
    }
    float rightCost[kBins] = {};
    Bounds right;
    uint32_t rightCount = 0;
    for (int b = kBins - 1; b > 0; --b)
    {
      right.Include(bins[b]);
      rightCount += binCount[b];
      rightCost[b] = right.HalfArea() * float(rightCount);
    }
    Bounds left;
    uint32_t leftCount = 0;
    float bestCost = 1e30f;
    int bestSplit = -1;
    for (int b = 1; b < kBins; ++b)
    {
      left.Include(bins[b - 1]);
      leftCount += binCount[b - 1];
      const float cost = left.HalfArea() * float(leftCount) + rightCost[b];
      if (leftCount > 0 && leftCount < task.count && cost < bestCost)
      {
        bestCost = cost;
        bestSplit = b;
      }
    }
    // A leaf when splitting costs more than testing everything here (1 traversal step ~ 1 test).
    const float leafCost = box.HalfArea() * float(task.count);
    if (bestSplit < 0 || (task.count <= uint32_t(maxLeafSize) && bestCost + box.HalfArea() >= leafCost))
      continue;
    const uint32_t* middle = std::partition(prims, prims + task.count, [&](uint32_t p) { return binOf(p) < bestSplit; });
    const uint32_t leftSize = uint32_t(middle - prims);

    const uint32_t child = uint32_t(tree.nodes.size());
    tree.nodes.push_back({});
    tree.nodes.push_back({});
    tree.nodes[task.node].left = child;  // `node` may dangle after push_back
    tree.nodes[task.node].right = child + 1;
    tasks.push_back({child + 1, task.first + leftSize, task.count - leftSize, task.depth + 1});
    tasks.push_back({child, task.first, leftSize, task.depth + 1});
  }
  return tree;
}

float SAHCost(const BVHTree& tree)
{
  if (tree.nodes.empty())
    return 0.0f;
  auto halfArea = [](const BVHNode& n) {
    const float3 e = max(n.boxMax - n.boxMin, float3(0.0f));
    return e.x * e.y + e.y * e.z + e.z * e.x;
  };
  const float rootArea = halfArea(tree.nodes[0]);
  if (rootArea <= 0.0f)
    return 0.0f;
  double cost = 0.0;
  for (const BVHNode& n : tree.nodes)
    cost += double(halfArea(n)) / rootArea * ((n.left & kLeafFlag) ? double(n.right) : 1.0);
  return float(cost);
}
