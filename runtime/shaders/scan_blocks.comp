#version 460
// Scan, pass 1: each workgroup scans a block of 1024 elements (4 per thread) with subgroup
// arithmetic and, for multi-block scans, writes the block's total. TYPE is uint, int or float.
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require

layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Input { TYPE src[]; };
layout(std430, binding = 1) writeonly buffer Output { TYPE dst[]; };  // may alias src
layout(std430, binding = 2) writeonly buffer BlockSums { TYPE blockSums[]; };
layout(push_constant) uniform Args
{
  uint n;
  uint inclusive;
  uint writeSums;
};

shared TYPE subgroupTotals[64];  // 256 threads / subgroups of >= 4

void main()
{
  const uint block = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint base = block * 1024u + gl_LocalInvocationIndex * 4u;
  TYPE v[4];
  for (uint k = 0; k < 4u; ++k)
    v[k] = base + k < n ? src[base + k] : TYPE(0);
  const TYPE threadSum = v[0] + v[1] + v[2] + v[3];
  const TYPE before = subgroupExclusiveAdd(threadSum);
  if (gl_SubgroupInvocationID == gl_SubgroupSize - 1u)
    subgroupTotals[gl_SubgroupID] = before + threadSum;
  barrier();
  if (gl_LocalInvocationIndex == 0u)
  {
    TYPE running = TYPE(0);  // subgroup totals become their exclusive prefix, in order
    for (uint s = 0; s < gl_NumSubgroups; ++s)
    {
      const TYPE t = subgroupTotals[s];
      subgroupTotals[s] = running;
      running += t;
    }
    if (writeSums != 0u)
      blockSums[block] = running;
  }
  barrier();
  TYPE acc = subgroupTotals[gl_SubgroupID] + before;
  for (uint k = 0; k < 4u; ++k)
  {
    const TYPE next = acc + v[k];
    if (base + k < n)
      dst[base + k] = inclusive != 0u ? next : acc;
    acc = next;
  }
}
