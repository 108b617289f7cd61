// The gang: what kernels may say about the threads that run beside them, in plain C++.
//
// On the ISPC backend a kernel runs in a gang of SIMD lanes (8 or 16 threads in step); on the CPU
// and in the original class one thread is a gang of one; Vulkan's GLSL runs each thread as a gang
// of one too. These functions let a kernel walk a structure together with its gang (packet
// traversal: one node loaded for all lanes, one stack), and in a gang of one they are what a
// single thread would do:
//
//   GangSize()        the lanes of the gang: programCount on ISPC, 1 elsewhere
//   AnyLane(b)        b holds in some active lane          (ISPC's any; b itself in a gang of one)
//   AllLanes(b)       b holds in every active lane         (ISPC's all)
//   FirstLane(v)      v in the first active lane, for all  (ISPC's extract at the lowest lane)
//   MinOverLanes(v)   the least v over the active lanes    (ISPC's reduce_min)
//   AllLanesOn()      every lane of the gang runs here: none was switched off by a branch, a loop
//                     or a return before this point        (ISPC: popcnt(lanemask()) == programCount)
//   LaneIndex()       this lane's place in the gang, 0 to GangSize() - 1      (ISPC's programIndex)
//   LaneBits(b)       the active lanes where b holds, as bits: bit i for lane i (ISPC's packmask)
//   LaneValue(v, i)   v in lane i, an active lane, for all      (ISPC's extract)
//   LaneOf(v, first)  component first + LaneIndex() of v, a LiteMath 4-vector, in the lanes where that
//                     is below 4, and the last component in the others: where v is a member or a
//                     CRT_UNIFORM local at an index the gang shares, ISPC reads the components in one
//                     load, not a gather
//   LaneOfQuad(v)     component LaneIndex() % 4 of v, a LiteMath 4-vector: each quad of four lanes holds
//                     all of v (a gang of 8 holds it twice, of 16 four times); from memory the gang
//                     shares, ISPC reads the components in one load and spreads them
//   FromLane(v, i)    v in lane i, where i may differ between lanes: each lane reads the lane it
//                     names, an active one (ISPC's shuffle; in a gang of one, i is 0 and this is v)
//
// With LaneIndex, the lanes of a gang can share out one thread's work: a loop
// `for (int first = 0; first < 4; first += GangSize())` (its start and bound shared) whose lanes
// take items first + LaneIndex() below 4 runs four times in a gang of one and once in a gang of four
// or more, and LaneBits and LaneValue bring the lanes' results back to values the gang shares
// (test/classes/gang_walk.cpp counts a query's keys so: those of its block of the table, and with
// LaneOf those of a float4). ISPC runs such a loop on every lane, those that a branch, a loop or a
// return switched off before it too (`unmasked`), so inside it LaneBits sees every lane; it may write
// only its own locals and CRT_UNIFORM ones, and may not return (diagnostics at the line otherwise).
//
// With LaneOfQuad and FromLane, a gang can share out the work of GangSize() / 4 threads, a quad of
// lanes each (BVHScene::TraceMeshQuads walks a few rays so, each quad a ray, each lane of a quad a box
// of a node, whose planes it reads with LaneOfQuad). FromLane reads lanes that may be off: call it
// where every lane is on (in the branch of an `if (AllLanesOn() && ...)`, or a loop stepping by
// GangSize()), as a lane that is off holds no value of its own there.
//
// In GLSL, where the gang is one thread, an `if` whose condition GangSize() decides alone
// (`GangSize() == 4 && ...`, `GangSize() > 1 && ...`) prints only the branch it takes, with a comment
// saying so: the shaders carry no walk written for wider gangs. Where the gang's term holds and the
// rest decides (`GangSize() == 1 && done`), the condition prints as the rest alone (`if (done)`).
//
// An `if` whose condition is AllLanesOn() && other terms every lane shares (AllLanes(...), GangSize(),
// members, CRT_UNIFORM locals) runs its then-branch on ISPC as `unmasked`: ISPC then knows that every
// lane is on, and keeps the branch's local structs (float3, float4, the user's) in registers. Under a
// mask it only knows at run time, each write to a field of a local struct is a masked store to
// memory, and a load that follows it waits for it (vmaskmovps with AVX2). Where the condition is not
// shared by every lane, the branch is printed as a plain `if`.
//
// CRT_UNIFORM before a local variable's declaration says the gang shares one copy of it (ISPC's
// `uniform`): it may only be assigned values every active lane agrees on (the results of the
// functions above, constants, members, members' elements at such indices, other CRT_UNIFORM
// variables); translated to ISPC, any other assignment, an element written at a per-lane index, or
// the local passed to a helper's non-const reference parameter is an error at its line. Assigned
// under a condition that differs between lanes, it changes for the whole gang.
//
// The contract: these decide how the lanes of a gang go together, never what a lane computes. A
// kernel must give every thread the result it would give alone (BVHScene's packet traversal finds
// each ray's nearest hit whichever rays share its gang), or the ISPC class and the others disagree.
#pragma once

#include <type_traits>

#if defined(__clang__)
#define CRT_UNIFORM [[clang::annotate("crossrt::uniform")]]
#else
#define CRT_UNIFORM
#endif

namespace crossrt {

inline int GangSize() { return 1; }
inline bool AnyLane(bool b) { return b; }
inline bool AllLanes(bool b) { return b; }
template <typename T>
inline T FirstLane(T v)
{
  return v;
}
template <typename T>
inline T MinOverLanes(T v)
{
  return v;
}
inline bool AllLanesOn() { return true; }
inline int LaneIndex() { return 0; }
inline unsigned LaneBits(bool b) { return b ? 1u : 0u; }
template <typename T>
inline T LaneValue(T v, int)
{
  return v;
}
template <typename V>
inline typename std::decay<decltype(std::declval<const V&>()[0])>::type LaneOf(const V& v, int first)
{
  return v[first + LaneIndex() < 3 ? first + LaneIndex() : 3];
}
template <typename V>
inline typename std::decay<decltype(std::declval<const V&>()[0])>::type LaneOfQuad(const V& v)
{
  return v[LaneIndex() % 4];
}
template <typename T>
inline T FromLane(T v, int)
{
  return v;
}

}  // namespace crossrt
