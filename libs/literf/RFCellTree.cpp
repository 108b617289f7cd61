#include "RFCellTree.h"

#include <algorithm>
#include <array>

namespace literf {

namespace {

using Cell = std::array<int, 3>;

struct Builder
{
  const RFGrid& grid;
  std::vector<RFNode>& nodes;

  LiteMath::float3 Corner(int x, int y, int z) const
  {
    const LiteMath::float3 step = (grid.boxMax - grid.boxMin) / float(grid.cells);
    return grid.boxMin + step * LiteMath::float3(float(x), float(y), float(z));
  }

  // Fills node `at` with the cells [first, last).
  void Build(uint32_t at, std::vector<Cell>& cells, size_t first, size_t last)
  {
    Cell lo = cells[first], hi = cells[first];
    for (size_t i = first; i < last; ++i)
      for (int a = 0; a < 3; ++a)
      {
        lo[a] = std::min(lo[a], cells[i][a]);
        hi[a] = std::max(hi[a], cells[i][a]);
      }
    RFNode node;
    node.boxMin = Corner(lo[0], lo[1], lo[2]);
    node.boxMax = Corner(hi[0] + 1, hi[1] + 1, hi[2] + 1);
    if (last - first == 1)
    {
      const Cell& c = cells[first];
      node.left = kCellLeaf | uint32_t(c[0] + grid.cells * (c[1] + grid.cells * c[2]));
      node.axis = 0;
      nodes[at] = node;
      return;
    }
    // The longest extent, split at the plane below the median cell: both sides keep a cell.
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (hi[a] - lo[a] > hi[axis] - lo[axis])
        axis = a;
    const size_t middle = first + (last - first) / 2;
    std::nth_element(cells.begin() + long(first), cells.begin() + long(middle), cells.begin() + long(last),
                     [axis](const Cell& a, const Cell& b) { return a[axis] < b[axis]; });
    int plane = cells[middle][axis];
    if (plane == lo[axis])
      plane += 1;  // the median sits on the lowest layer: the layer alone goes left
    const auto split = std::partition(cells.begin() + long(first), cells.begin() + long(last), [&](const Cell& c) { return c[axis] < plane; });
    const size_t mid = size_t(split - cells.begin());
    node.left = uint32_t(nodes.size());
    node.axis = uint32_t(axis);
    nodes[at] = node;
    nodes.resize(nodes.size() + 2);
    const uint32_t left = node.left;
    Build(left, cells, first, mid);
    Build(left + 1, cells, mid, last);
  }
};

}  // namespace

std::vector<RFNode> BuildCellTree(const RFGrid& grid)
{
  const std::vector<uint8_t> occupied = OccupiedCells(grid);
  std::vector<Cell> cells;
  const int n = grid.cells;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        if (occupied[size_t(x) + size_t(n) * (size_t(y) + size_t(n) * size_t(z))])
          cells.push_back({x, y, z});
  std::vector<RFNode> nodes;
  if (cells.empty())
    return nodes;
  nodes.reserve(2 * cells.size());
  nodes.resize(1);
  Builder{grid, nodes}.Build(0, cells, 0, cells.size());
  return nodes;
}

}  // namespace literf
