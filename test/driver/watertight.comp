#version 460
// One ray per thread from inside a closed mesh, with a ray query: the nearest
// triangle's index and distance, or 0xFFFFFFFF where the ray leaves the mesh without a hit.
#extension GL_EXT_ray_query : require
layout(local_size_x = 64) in;
layout(binding = 0) uniform accelerationStructureEXT scene;
layout(std430, binding = 1) readonly buffer Rays { vec4 rays[]; };  // origin, direction
layout(std430, binding = 2) writeonly buffer Hits { uvec2 hits[]; };  // primitive, floatBitsToUint(t)
layout(push_constant) uniform Count { uint count; };

void main()
{
  const uint i = gl_GlobalInvocationID.x;
  if (i >= count)
    return;
  rayQueryEXT query;
  rayQueryInitializeEXT(query, scene, gl_RayFlagsOpaqueEXT, 0xFF, rays[2 * i].xyz, 0.0, rays[2 * i + 1].xyz, 1e30);
  while (rayQueryProceedEXT(query))
    ;
  if (rayQueryGetIntersectionTypeEXT(query, true) == gl_RayQueryCommittedIntersectionTriangleEXT)
    hits[i] = uvec2(uint(rayQueryGetIntersectionPrimitiveIndexEXT(query, true)), floatBitsToUint(rayQueryGetIntersectionTEXT(query, true)));
  else
    hits[i] = uvec2(0xFFFFFFFFu, 0u);
}
