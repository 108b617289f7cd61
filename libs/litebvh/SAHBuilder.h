// A binned SAH builder (top-down, 32 bins on the widest axis of the centers), single-threaded:
// slower to build than the LBVH, better trees. Both write BVHNode trees, so the same traversal
// reads either and the benchmark can trade build time against trace time.
#pragma once
#include "BVHNode.h"
#include "LiteMath.h"

// Builds over boxes[0, count). Leaves hold at most maxLeafSize primitives, except where the
// centers of more coincide and no split separates them.
BVHTree BuildBinnedSAH(const LiteMath::Box4f* boxes, int count, int maxLeafSize = 4);

// The surface area heuristic cost of a tree, relative to its root's area: 1 per inner node
// visited and 1 per primitive tested. Lower is better; the same measure for every builder.
float SAHCost(const BVHTree& tree);
