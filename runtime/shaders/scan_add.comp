#version 460
// Scan, pass 2: adds each block's offset (the exclusive scan of the block totals) and the
// initial value to the block's elements. TYPE is uint, int or float.
layout(local_size_x = 256) in;
layout(std430, binding = 0) buffer Data { TYPE data[]; };
layout(std430, binding = 1) readonly buffer BlockOffsets { TYPE blockOffsets[]; };
layout(push_constant) uniform Args
{
  uint n;
  uint hasOffsets;
  TYPE init;
};

void main()
{
  const uint block = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint base = block * 1024u + gl_LocalInvocationIndex * 4u;
  const TYPE offset = (hasOffsets != 0u ? blockOffsets[block] : TYPE(0)) + init;
  for (uint k = 0; k < 4u; ++k)
    if (base + k < n)
      data[base + k] += offset;
}
