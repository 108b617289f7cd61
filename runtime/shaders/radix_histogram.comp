#version 460
#extension GL_GOOGLE_include_directive : require
// Radix sort, pass 1 of each digit: every workgroup counts the 8-bit digits of its tile of 1024
// keys. Counts are stored digit-major (count[digit * tiles + tile]), so that one exclusive scan
// gives each (digit, tile) its first output position.
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Records { uint records[]; };
layout(std430, binding = 1) writeonly buffer Counts { uint counts[]; };
layout(std430, binding = 2) readonly buffer Count { uint countWords[]; };
#include "radix_key.glsl"

shared uint histogram[256];

void main()
{
  const uint tile = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint t = gl_LocalInvocationIndex;
  const uint count = RecordCount();
  histogram[t] = 0u;
  barrier();
  for (uint r = 0u; r < 4u; ++r)
  {
    const uint i = tile * 1024u + r * 256u + t;
    if (i < count)
      atomicAdd(histogram[(SortableKey(records[i * stride + keyWord]) >> shift) & 255u], 1u);
  }
  barrier();
  counts[t * tiles + tile] = histogram[t];
}
