#include "LBVH.h"

#include <algorithm>
#include <numeric>

using LiteMath::Box4f;
using LiteMath::float3;
using LiteMath::uint2;

void LBVH::Reserve(int maxBoxes)
{
  const size_t n = size_t(std::max(maxBoxes, 1));
  m_nodes.resize(2 * n - 1);
  m_primIndices.resize(n);
  m_codes.resize(n);
  m_newGroup.resize(n);
  m_groupOf.resize(n);
  m_leafFirst.resize(n);
  m_leafCode.resize(n);
  m_parent.resize(2 * n - 1);
  m_arrivals.resize(n);
}

void LBVH::Build(int count, const Box4f* boxes)
{
  // (0) input => bounds of the centers
  m_centerMin = float3(+1e30f);
  m_centerMax = float3(-1e30f);
  kernel1D_Bounds(count, boxes);
  // (1) input => m_codes
  kernel1D_EvalMC(count, boxes);
  // (2) sort by Morton code
  std::sort(m_codes.begin(), m_codes.begin() + count, [](uint2 a, uint2 b) { return a.x < b.x; });
  // (3) one leaf per distinct code: mark, scan, compact
  kernel1D_AppendInit(count);
  std::exclusive_scan(m_newGroup.begin(), m_newGroup.begin() + count, m_groupOf.begin(), 0u);
  m_leafCount = 0;
  kernel1D_AppendComplete(count);
  // (4) the hierarchy over the leaves
  kernel1D_Karras12(count);
  // (5) the leaves from their triangles' boxes
  kernel1D_MakeLeaves(count, boxes);
  // (6) the inner nodes from the leaves up. With the leaves done, only a node whose children are
  // both inner needs an atomic, a third of them or so (making the leaves here, every node did).
  kernel1D_Refit(count);
}

BVHTree LBVH::Tree(int count) const
{
  BVHTree tree;
  if (count <= 0 || m_leafCount == 0)
    return tree;
  tree.nodes.assign(m_nodes.begin(), m_nodes.begin() + (2 * m_leafCount - 1));
  tree.primIndices.assign(m_primIndices.begin(), m_primIndices.begin() + count);
  return tree;
}

void LBVH::kernel1D_Bounds(int count, const Box4f* boxes)
{
  for (int i = 0; i < count; i++)
  {
    const float3 center = 0.5f * (to_float3(boxes[i].boxMin) + to_float3(boxes[i].boxMax));
    m_centerMin = min(m_centerMin, center);
    m_centerMax = max(m_centerMax, center);
  }
}

void LBVH::kernel1D_EvalMC(int count, const Box4f* boxes)
{
  for (int i = 0; i < count; i++)
  {
    const float3 center = 0.5f * (to_float3(boxes[i].boxMin) + to_float3(boxes[i].boxMax));
    const float3 extent = m_centerMax - m_centerMin;
    // A flat axis (all centers equal along it) contributes zeros.
    const float3 scale = float3(extent.x > 0.0f ? 1023.0f / extent.x : 0.0f, extent.y > 0.0f ? 1023.0f / extent.y : 0.0f,
                                extent.z > 0.0f ? 1023.0f / extent.z : 0.0f);
    const float3 cell = clamp((center - m_centerMin) * scale, float3(0.0f), float3(1023.0f));
    const uint32_t code = (MortonExpandBits(uint32_t(cell.x)) << 2) | (MortonExpandBits(uint32_t(cell.y)) << 1) | MortonExpandBits(uint32_t(cell.z));
    m_codes[i] = uint2(code, uint32_t(i));
  }
}

void LBVH::kernel1D_AppendInit(int count)
{
  for (int i = 0; i < count; i++)
  {
    m_newGroup[i] = (i == 0 || m_codes[i].x != m_codes[i - 1].x) ? 1u : 0u;
    m_primIndices[i] = m_codes[i].y;
  }
}

void LBVH::kernel1D_AppendComplete(int count)
{
  for (int i = 0; i < count; i++)
  {
    if (m_newGroup[i] != 0u)
    {
      m_leafFirst[m_groupOf[i]] = uint32_t(i);
      m_leafCode[m_groupOf[i]] = m_codes[i].x;
    }
    if (i == count - 1)
      m_leafCount += m_groupOf[i] + m_newGroup[i];
  }
}

void LBVH::kernel1D_Karras12(int count)
{
  for (int i = 0; i < count; i++)
  {
    const int leaves = int(m_leafCount);
    if (i >= leaves - 1)
      continue;
    const uint32_t code = m_leafCode[i];
    // Direction of the range: towards the neighbour sharing the longer prefix.
    const int d = CommonPrefix(code, i + 1) > CommonPrefix(code, i - 1) ? 1 : -1;
    // Upper bound of the range's length, then its exact other end j by binary search.
    const int deltaMin = CommonPrefix(code, i - d);
    int lengthMax = 2;
    while (CommonPrefix(code, i + lengthMax * d) > deltaMin)
      lengthMax *= 2;
    int length = 0;
    for (int step = lengthMax / 2; step >= 1; step /= 2)
      if (CommonPrefix(code, i + (length + step) * d) > deltaMin)
        length += step;
    const int j = i + length * d;
    // The split: the last leaf sharing more than the range's common prefix with i.
    const int deltaNode = CommonPrefix(code, j);
    int split = 0;
    for (int divisor = 2; divisor < 2 * length + 2; divisor *= 2)
    {
      const int step = (length + divisor - 1) / divisor;
      if (CommonPrefix(code, i + (split + step) * d) > deltaNode)
        split += step;
      if (step == 1)
        break;
    }
    const int gamma = i + split * d + std::min(d, 0);
    const int first = std::min(i, j), last = std::max(i, j);
    const uint32_t left = uint32_t(first == gamma ? leaves - 1 + gamma : gamma);
    const uint32_t right = uint32_t(last == gamma + 1 ? leaves + gamma : gamma + 1);
    m_nodes[i].left = left;
    m_nodes[i].right = right;
    m_parent[left] = uint32_t(i);
    m_parent[right] = uint32_t(i);
    m_arrivals[i] = 0u;
  }
}

void LBVH::kernel1D_MakeLeaves(int count, const Box4f* boxes)
{
  for (int leaf = 0; leaf < count; leaf++)
  {
    if (uint32_t(leaf) >= m_leafCount)
      continue;
    const uint32_t first = m_leafFirst[leaf];
    const uint32_t last = uint32_t(leaf) + 1 < m_leafCount ? m_leafFirst[leaf + 1] : uint32_t(count);
    float3 boxMin = float3(+1e30f), boxMax = float3(-1e30f);
    for (uint32_t k = first; k < last; k++)
    {
      const Box4f box = boxes[m_primIndices[k]];
      boxMin = min(boxMin, to_float3(box.boxMin));
      boxMax = max(boxMax, to_float3(box.boxMax));
    }
    const uint32_t node = m_leafCount - 1 + uint32_t(leaf);  // leaves follow the leafCount - 1 inner nodes
    m_nodes[node].boxMin = boxMin;
    m_nodes[node].boxMax = boxMax;
    m_nodes[node].left = kLeafFlag | first;
    m_nodes[node].right = last - first;
  }
}

void LBVH::kernel1D_Refit(int count)
{
  for (int leaf = 0; leaf < count; leaf++)
  {
    if (uint32_t(leaf) >= m_leafCount)
      continue;
    const uint32_t firstLeaf = m_leafCount - 1;
    uint32_t node = firstLeaf + uint32_t(leaf);
    float3 boxMin = m_nodes[node].boxMin, boxMax = m_nodes[node].boxMax;
    while (node != 0u)
    {
      const uint32_t parent = m_parent[node];
      const uint32_t left = m_nodes[parent].left, right = m_nodes[parent].right;
      const uint32_t sibling = left == node ? right : left;
      if (sibling >= firstLeaf)  // a leaf, done: of two leaves, the left one's thread goes on
      {
        if (node >= firstLeaf && node == right)
          break;
      }
      else if (node >= firstLeaf)  // the inner sibling's thread will find this leaf done
        break;
      else if (crossrt::AtomicAdd(m_arrivals[parent], 1u) == 0u)  // two inner children: the second goes on
        break;
      boxMin = min(boxMin, m_nodes[sibling].boxMin);
      boxMax = max(boxMax, m_nodes[sibling].boxMax);
      m_nodes[parent].boxMin = boxMin;
      m_nodes[parent].boxMax = boxMax;
      node = parent;
    }
  }
}

BVHTree BuildLBVH(LBVH& builder, const Box4f* boxes, int count)
{
  if (count <= 0)
    return BVHTree{};
  if (builder.Capacity() < count)
  {
    builder.Reserve(count);
    builder.CommitDeviceData();
  }
  builder.Build(count, boxes);
  return builder.Tree(count);
}
