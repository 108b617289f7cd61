#version 460
// Radix sort, pass 1 of each digit: every workgroup counts the 8-bit digits of its tile of 1024
// keys. Counts are stored digit-major (count[digit * tiles + tile]), so that one exclusive scan
// gives each (digit, tile) its first output position.
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Keys { uint keys[]; };
layout(std430, binding = 1) writeonly buffer Counts { uint counts[]; };
layout(push_constant) uniform Args { uint n; uint shift; uint tiles; };

shared uint histogram[256];

void main()
{
  const uint tile = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint t = gl_LocalInvocationIndex;
  histogram[t] = 0u;
  barrier();
  for (uint r = 0u; r < 4u; ++r)
  {
    const uint i = tile * 1024u + r * 256u + t;
    if (i < n)
      atomicAdd(histogram[(keys[i] >> shift) & 255u], 1u);
  }
  barrier();
  counts[t * tiles + tile] = histogram[t];
}
