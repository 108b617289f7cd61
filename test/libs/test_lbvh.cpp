// The LBVH builder as written (single-threaded C++), translated for all CPU cores (LBVH_CPU; and
// LBVH_ISPC, in SIMD lanes too, where ISPC is found) and translated for Vulkan (LBVH_Vulkan, on
// lavapipe with validation on). Every tree is checked for
// structure (each primitive in exactly one leaf, each node reached once, each box exactly the union
// of its children's), and the translated trees must equal the original's node for node: the codes
// are unique after grouping, so the hierarchy is determined; only the order of primitives inside a
// leaf may differ (std::sort is not stable, the GPU radix sort is).
#include "LBVH.h"
#include "LBVH_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "LBVH_ISPC.h"
#endif
#include "LBVH_Vulkan.h"
#include "TestSupport.h"

#include <algorithm>
#include <random>
#include <string>

using LiteMath::Box4f;
using LiteMath::float3;
using LiteMath::float4;

namespace {

bool SameBox(float3 aMin, float3 aMax, float3 bMin, float3 bMax)
{
  return aMin.x == bMin.x && aMin.y == bMin.y && aMin.z == bMin.z && aMax.x == bMax.x && aMax.y == bMax.y && aMax.z == bMax.z;
}

// Empty when `tree` is a valid BVH over boxes[0, count); else what is wrong first.
std::string CheckTree(const BVHTree& tree, const std::vector<Box4f>& boxes)
{
  const size_t count = boxes.size();
  if (tree.primIndices.size() != count) return "primIndices has " + std::to_string(tree.primIndices.size()) + " entries";
  std::vector<int> primSeen(count, 0), nodeSeen(tree.nodes.size(), 0);
  std::vector<uint32_t> stack = {0};
  while (!stack.empty())
  {
    const uint32_t n = stack.back();
    stack.pop_back();
    if (n >= tree.nodes.size() || nodeSeen[n]++) return "node " + std::to_string(n) + " out of range or reached twice";
    const BVHNode& node = tree.nodes[n];
    float3 lo(1e30f), hi(-1e30f);
    if (node.left & kLeafFlag)
    {
      const uint32_t first = node.left & ~kLeafFlag;
      if (node.right == 0 || first + node.right > count) return "leaf " + std::to_string(n) + " has a bad range";
      for (uint32_t k = first; k < first + node.right; ++k)
      {
        const uint32_t p = tree.primIndices[k];
        if (p >= count || primSeen[p]++) return "primitive " + std::to_string(p) + " out of range or in two leaves";
        lo = min(lo, to_float3(boxes[p].boxMin));
        hi = max(hi, to_float3(boxes[p].boxMax));
      }
    }
    else
    {
      for (uint32_t c : {node.left, node.right})
      {
        if (c >= tree.nodes.size()) return "node " + std::to_string(n) + " has child " + std::to_string(c);
        lo = min(lo, tree.nodes[c].boxMin);
        hi = max(hi, tree.nodes[c].boxMax);
        stack.push_back(c);
      }
    }
    if (!SameBox(lo, hi, node.boxMin, node.boxMax)) return "node " + std::to_string(n) + " box is not the union of its contents";
  }
  if (std::count(nodeSeen.begin(), nodeSeen.end(), 1) != long(tree.nodes.size())) return "unreachable nodes";
  return "";
}

// Small random triangles' boxes; `clustered` puts every center at one point (all Morton codes equal).
std::vector<Box4f> RandomBoxes(int n, uint32_t seed, bool clustered)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f), s(0.001f, 0.5f);
  std::vector<Box4f> boxes(n);
  for (auto& b : boxes)
  {
    const float3 c = clustered ? float3(1.0f, 2.0f, 3.0f) : float3(u(rng), u(rng), u(rng));
    const float3 e(s(rng), s(rng), s(rng));
    b = Box4f(float4(c.x - e.x, c.y - e.y, c.z - e.z, 0.0f), float4(c.x + e.x, c.y + e.y, c.z + e.z, 0.0f));
  }
  return boxes;
}

BVHTree BuildWith(LBVH& builder, const std::vector<Box4f>& boxes)
{
  builder.Reserve(int(boxes.size()));
  builder.CommitDeviceData();
  builder.Build(int(boxes.size()), boxes.data());
  return builder.Tree(int(boxes.size()));
}

}  // namespace

// Centers whose Morton codes are 0, 1, 2, 4, ..., 2^29 and 2^30 - 1: each code shares one more
// leading bit with the next, so the tree is a chain 30 inner nodes deep, the most a 30-bit code
// allows: the refit climbs all of it, one thread reaching the root through every level.
TEST_CASE("LBVH: the deepest tree 30-bit codes allow is refit to the root on every backend", "[lbvh][equivalence]")
{
  auto ctx = ValidatedContext();
  std::vector<Box4f> boxes;
  auto add = [&](float x, float y, float z) { boxes.push_back(Box4f(float4(x, y, z, 0.0f) - 0.25f, float4(x, y, z, 0.0f) + 0.25f)); };
  add(0.0f, 0.0f, 0.0f);
  add(1023.0f, 1023.0f, 1023.0f);  // the scene's extent: 1023 cells of size 1 per axis
  for (int k = 0; k < 30; ++k)  // bit k of a code is axis 2 - k % 3's bit k / 3 (z is the lowest)
  {
    const float cell = float(1 << (k / 3));
    add(k % 3 == 2 ? cell : 0.0f, k % 3 == 1 ? cell : 0.0f, k % 3 == 0 ? cell : 0.0f);
  }
  auto depth = [](const BVHTree& tree) {
    int deepest = 0;
    std::vector<std::pair<uint32_t, int>> todo = {{0u, 0}};
    while (!todo.empty())
    {
      const auto [n, d] = todo.back();
      todo.pop_back();
      deepest = std::max(deepest, d);
      if (!(tree.nodes[n].left & kLeafFlag))
        todo.insert(todo.end(), {{tree.nodes[n].left, d + 1}, {tree.nodes[n].right, d + 1}});
    }
    return deepest;
  };
  LBVH original;
  const BVHTree expected = BuildWith(original, boxes);
  REQUIRE(original.m_leafCount == 32u);
  CHECK(depth(expected) >= 30);  // 31 levels of inner nodes above the deepest leaf pair
  REQUIRE(CheckTree(expected, boxes) == "");
  std::vector<std::pair<const char*, std::shared_ptr<LBVH>>> translated = {{"CPU", CreateLBVH_CPU()}};
#ifdef CROSSRT_HAS_ISPC
  translated.push_back({"ISPC", CreateLBVH_ISPC()});
#endif
  if (ctx) translated.push_back({"Vulkan", CreateLBVH_Vulkan(ctx)});
  for (auto& [name, impl] : translated)
  {
    INFO(name);
    REQUIRE(CheckTree(BuildWith(*impl, boxes), boxes) == "");
  }
  RequireNoValidationMessages(ctx);
}

TEST_CASE("LBVH: the original, LBVH_CPU, LBVH_ISPC and LBVH_Vulkan build the same valid tree", "[lbvh][equivalence]")
{
  auto ctx = ValidatedContext();
  struct Case { int n; bool clustered; };
  for (Case c : {Case{1, false}, Case{2, false}, Case{3, false}, Case{1000, false}, Case{70001, false}, Case{500, true}})
  {
    DYNAMIC_SECTION("n = " << c.n << (c.clustered ? ", one shared center" : ""))
    {
      const auto boxes = RandomBoxes(c.n, uint32_t(c.n), c.clustered);
      LBVH original;
      const BVHTree expected = BuildWith(original, boxes);
      REQUIRE(CheckTree(expected, boxes) == "");
      REQUIRE(expected.nodes.size() == 2 * original.m_leafCount - 1);
      if (c.clustered) REQUIRE(original.m_leafCount == 1);  // every code equal: one leaf holds everything
      if (c.n == 70001) REQUIRE(original.m_leafCount > 60000u);  // equal codes are rare at this density

      std::vector<std::pair<const char*, std::shared_ptr<LBVH>>> translated = {{"CPU", CreateLBVH_CPU()}};
#ifdef CROSSRT_HAS_ISPC
      translated.push_back({"ISPC", CreateLBVH_ISPC()});
#endif
      if (ctx) translated.push_back({"Vulkan", CreateLBVH_Vulkan(ctx)});
      for (auto& [name, impl] : translated)
      {
        INFO(name);
        const BVHTree tree = BuildWith(*impl, boxes);
        REQUIRE(CheckTree(tree, boxes) == "");
        REQUIRE(impl->m_leafCount == original.m_leafCount);
        REQUIRE(tree.nodes.size() == expected.nodes.size());
        size_t differentNodes = 0;
        for (size_t i = 0; i < tree.nodes.size(); ++i)
        {
          const BVHNode &a = tree.nodes[i], &b = expected.nodes[i];
          differentNodes += a.left != b.left || a.right != b.right || !SameBox(a.boxMin, a.boxMax, b.boxMin, b.boxMax);
        }
        if (std::string(name) == "CPU" || RoundsLikeTheCpu(*ctx))
          REQUIRE(differentNodes == 0);
        else  // a Morton code's scale is a quotient: a GPU's may differ in the last bit
        {
          if (differentNodes > 0) WARN(differentNodes << " of " << tree.nodes.size() << " nodes differ on " << ctx->DeviceName());
          REQUIRE(differentNodes <= tree.nodes.size() / 100);
        }
      }
    }
  }
  RequireNoValidationMessages(ctx);
}
