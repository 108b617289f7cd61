#version 460
// Indirect dispatch, step 1: turns a thread count that kernels computed on the GPU (the size of a
// std::vector they appended to, capped at its capacity) into the group counts of a
// VkDispatchIndirectCommand, spread over y like crossrt::Dispatch1D beyond maxGroupsX groups.
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer Counts { uint words[]; };
layout(std430, binding = 1) writeonly buffer Groups { uint groups[3]; };
layout(push_constant) uniform Args
{
  uint sizeWord;      // index of the thread count in `words`
  uint capacityWord;  // index of its cap
  uint groupSize;
  uint maxGroupsX;
};

void main()
{
  const uint threads = min(words[sizeWord], words[capacityWord]);
  const uint total = (threads + groupSize - 1u) / groupSize;
  const uint rows = (total + maxGroupsX - 1u) / maxGroupsX;
  groups[0] = rows == 0u ? 0u : (total + rows - 1u) / rows;  // balanced over the rows, as Dispatch1D
  groups[1] = rows;
  groups[2] = 1u;
}
