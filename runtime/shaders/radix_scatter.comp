#version 460
#extension GL_GOOGLE_include_directive : require
// Radix sort, pass 2 of each digit: every workgroup moves its tile's records to their sorted
// positions. Stable: records keep their order within a digit. Each of 4 rounds takes 256
// consecutive records; a record's rank among equal digits of the round comes from a bitmask per
// digit.
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer RecordsIn { uint recordsIn[]; };
layout(std430, binding = 1) writeonly buffer RecordsOut { uint recordsOut[]; };
layout(std430, binding = 2) readonly buffer Offsets { uint offsets[]; };  // scanned counts
layout(std430, binding = 3) readonly buffer Count { uint countWords[]; };
#include "radix_key.glsl"

shared uint masks[256][8];   // per digit: which threads of this round hold it
shared uint placed[256];     // per digit: records of this tile already placed

void main()
{
  const uint tile = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint t = gl_LocalInvocationIndex;
  const uint count = RecordCount();
  placed[t] = offsets[t * tiles + tile];
  for (uint w = 0u; w < 8u; ++w)
    masks[t][w] = 0u;
  barrier();
  for (uint r = 0u; r < 4u; ++r)
  {
    const uint i = tile * 1024u + r * 256u + t;
    const bool valid = i < count;
    const uint digit = valid ? (SortableKey(recordsIn[i * stride + keyWord]) >> shift) & 255u : 0u;
    if (valid)
      atomicOr(masks[digit][t / 32u], 1u << (t % 32u));
    barrier();
    if (valid)
    {
      uint rank = 0u;  // threads before t in this round with the same digit
      for (uint w = 0u; w < t / 32u; ++w)
        rank += bitCount(masks[digit][w]);
      rank += bitCount(masks[digit][t / 32u] & ((1u << (t % 32u)) - 1u));
      const uint position = placed[digit] + rank;
      for (uint w = 0u; w < stride; ++w)
        recordsOut[position * stride + w] = recordsIn[i * stride + w];
    }
    barrier();
    // Thread t owns digit t: advance past this round's records, clear its masks.
    uint total = 0u;
    for (uint w = 0u; w < 8u; ++w)
    {
      total += bitCount(masks[t][w]);
      masks[t][w] = 0u;
    }
    placed[t] += total;
    barrier();
  }
}
