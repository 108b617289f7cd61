// The node format every CrossRT BVH builder writes (BVHScene collapses it into 4-wide nodes for its
// traversal: BVH4Node in libs/litert/BVHScene.h).
#pragma once
#include "LiteMath.h"

#include <cstdint>
#include <vector>

// 32 bytes, the same layout in C++ and in GLSL's std430. An inner node's left/right are child node
// indices. A leaf has left = kLeafFlag | (first entry in the primitive index array) and right =
// the number of primitives.
struct BVHNode
{
  LiteMath::float3 boxMin;
  uint32_t left;
  LiteMath::float3 boxMax;
  uint32_t right;
};

constexpr uint32_t kLeafFlag = 0x80000000u;

// A built tree: nodes[0] is the root (a leaf when there is one group of primitives), and leaves
// reference ranges of primIndices. Empty when built over no primitives.
struct BVHTree
{
  std::vector<BVHNode> nodes;
  std::vector<uint32_t> primIndices;
};
