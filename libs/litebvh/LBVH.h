// A linear BVH builder (Karras 2012) written as plain single-threaded C++ in CrossRT's kernel
// conventions, so that the same class runs as written, translated to all CPU cores (LBVH_CPU) and
// translated to Vulkan (LBVH_Vulkan). The steps follow the paper's listing 3: a reduction for the
// bounds, Morton codes, a sort, grouping of equal codes into leaves with a scan, the Karras
// hierarchy, and a bottom-up refit in one pass (a thread climbs from each leaf; at a node with two
// inner children, the second to arrive finishes it).
#pragma once
#include "Atomics.h"
#include "BVHNode.h"
#include "LiteMath.h"

#include <cstdint>
#include <vector>

// Spreads the low 10 bits of v to every third bit (one axis of a 30-bit Morton code).
inline uint32_t MortonExpandBits(uint32_t v)
{
  v = (v * 0x00010001u) & 0xFF0000FFu;
  v = (v * 0x00000101u) & 0x0F00F00Fu;
  v = (v * 0x00000011u) & 0xC30C30C3u;
  v = (v * 0x00000005u) & 0x49249249u;
  return v;
}

class LBVH
{
public:
  LBVH() = default;
  virtual ~LBVH() = default;

  // Sizes the work arrays for up to maxBoxes boxes. Call it, then CommitDeviceData(), before
  // building over more boxes than the last Reserve allowed.
  void Reserve(int maxBoxes);
  // Builds over boxes[0, count) (0 < count <= the reserved size): m_nodes[0, 2 * leaves - 1) with the
  // root at 0, and m_primIndices[0, count). Leaves group the boxes whose Morton codes are equal.
  virtual void Build(int count, [[crossrt::size("count")]] const LiteMath::Box4f* boxes);
  // The tree of the last Build, trimmed to its size.
  BVHTree Tree(int count) const;
  // Boxes the work arrays hold (the last Reserve).
  int Capacity() const { return int(m_codes.size()); }

  virtual void CommitDeviceData() {}
  virtual void GetExecutionTime(const char* a_funcName, float a_out[4]) { (void)a_funcName; a_out[0] = a_out[1] = a_out[2] = a_out[3] = 0.0f; }

  std::vector<BVHNode> m_nodes;
  std::vector<uint32_t> m_primIndices;
  uint32_t m_leafCount = 0;  // leaves of the last build

protected:
  // (0) bounds of the box centers
  void kernel1D_Bounds(int count, const LiteMath::Box4f* boxes);
  // (1) m_codes[i] = (Morton code of box i's center, i)
  void kernel1D_EvalMC(int count, const LiteMath::Box4f* boxes);
  // (3) after the sort: mark where a new code starts, and the primitive order
  void kernel1D_AppendInit(int count);
  // (3) after the scan: the first sorted box and the code of every leaf
  void kernel1D_AppendComplete(int count);
  // (4) the inner nodes' children from the leaves' codes, and each node's parent
  void kernel1D_Karras12(int count);
  // (5) each leaf gets its box and primitive range
  void kernel1D_MakeLeaves(int count, const LiteMath::Box4f* boxes);
  // (6) from the leaves up, one thread per leaf: a node is finished by the thread coming from its
  // left leaf when both children are leaves, from its inner child when one is, and from the second
  // to arrive (crossrt::AtomicAdd) when both are inner; the others stop
  void kernel1D_Refit(int count);
  // Karras's delta(i, j): the length of the common prefix of leaf i's code, `code` (which Karras12's
  // searches compare with many others: read once, one load fewer per step in SIMD lanes), and leaf
  // j's; -1 when j is outside the leaves. Defined here so that the translated CPU class, compiled
  // apart, can inline it into Karras12's searches.
  int CommonPrefix(uint32_t code, int j) const
  {
    if (j < 0 || j >= int(m_leafCount))
      return -1;
    return __builtin_clz(code ^ m_leafCode[j]);
  }

  LiteMath::float3 m_centerMin, m_centerMax;
  std::vector<LiteMath::uint2> m_codes;  // (Morton code, box index)
  std::vector<uint32_t> m_newGroup;      // 1 where a sorted code differs from the one before
  std::vector<uint32_t> m_groupOf;       // leaf of each sorted box (exclusive scan of m_newGroup)
  std::vector<uint32_t> m_leafFirst;     // first sorted box of each leaf
  std::vector<uint32_t> m_leafCode;      // Morton code of each leaf, strictly increasing
  std::vector<uint32_t> m_parent;        // per node: its parent (the root's is unused)
  std::vector<uint32_t> m_arrivals;      // per inner node: children that reached it in the refit
};

// Builds with `builder` (the class as written or a translated one) over boxes[0, count), reserving
// and committing its arrays when count exceeds what they hold. Empty tree for count <= 0.
BVHTree BuildLBVH(LBVH& builder, const LiteMath::Box4f* boxes, int count);
