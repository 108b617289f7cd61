// The paper's acceleration structure for ReLU fields (section 4.3): a tree over the occupied cells of
// the grid only, which a ray visits strictly front to back. Each inner node splits its cells by a
// plane between grid cells, so its two children never overlap and the child on the ray's side of
// the plane comes first. A leaf is one cell.
#pragma once
#include "RFGrid.h"

namespace literf {

// 32 bytes, the same in C++ and in a GPU buffer (std430).
struct RFNode
{
  LiteMath::float3 boxMin;
  uint32_t left;  // inner: its children are nodes left and left + 1; a leaf: kCellLeaf | cell index
  LiteMath::float3 boxMax;
  uint32_t axis;  // inner: the axis of its splitting plane (0, 1, 2); the left child lies below it
};

constexpr uint32_t kCellLeaf = 0x80000000u;

// The tree over the cells OccupiedCells() marks; node 0 is the root. Empty when no cell is occupied.
std::vector<RFNode> BuildCellTree(const RFGrid& grid);

}  // namespace literf
