#version 460
// Radix sort, pass 2 of each digit: every workgroup moves its tile's keys (and values) to their
// sorted positions. Stable: keys keep their order within a digit. Each of 4 rounds takes 256
// consecutive keys; a key's rank among equal digits of the round comes from a bitmask per digit.
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer KeysIn { uint keysIn[]; };
layout(std430, binding = 1) readonly buffer ValuesIn { uint valuesIn[]; };
layout(std430, binding = 2) writeonly buffer KeysOut { uint keysOut[]; };
layout(std430, binding = 3) writeonly buffer ValuesOut { uint valuesOut[]; };
layout(std430, binding = 4) readonly buffer Offsets { uint offsets[]; };  // scanned counts
layout(push_constant) uniform Args { uint n; uint shift; uint tiles; };

shared uint masks[256][8];   // per digit: which threads of this round hold it
shared uint placed[256];     // per digit: keys of this tile already placed

void main()
{
  const uint tile = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint t = gl_LocalInvocationIndex;
  placed[t] = offsets[t * tiles + tile];
  for (uint w = 0u; w < 8u; ++w)
    masks[t][w] = 0u;
  barrier();
  for (uint r = 0u; r < 4u; ++r)
  {
    const uint i = tile * 1024u + r * 256u + t;
    const bool valid = i < n;
    const uint key = valid ? keysIn[i] : 0u;
    const uint digit = (key >> shift) & 255u;
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
      keysOut[position] = key;
      valuesOut[position] = valuesIn[i];
    }
    barrier();
    // Thread t owns digit t: advance past this round's keys, clear its masks.
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
