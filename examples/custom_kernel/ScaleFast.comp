#version 460
// Hand-written replacement of VectorOps::kernel1D_Scale: four elements per thread.
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Data { float data[]; };
layout(push_constant) uniform Args { uint n; float factor; };

void main()
{
  const uint first = gl_GlobalInvocationID.x * 4;
  for (uint i = first; i < min(first + 4, n); ++i)
    data[i] *= factor;
}
