// Input rules every ISceneObject implementation in litert applies the same way.
#pragma once
#include "LiteMath.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace litert_detail
{
// Throws std::invalid_argument (message prefixed by `who`) for a mesh that would be read out of
// bounds: an index count not a multiple of 3, null data, a short stride, an index >= vertNum.
// Also a vertex that a triangle uses and that has a NaN or infinite coordinate (it would change
// every bound it joins, or crash a builder).
void ValidateMesh(const char* who, const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum,
                  size_t vByteStride);

// Throws std::invalid_argument (prefixed by `who`) for an instance matrix with a NaN or infinite
// entry, or one that is singular (no inverse: rays could not be moved into the object's space).
void ValidateInstanceMatrix(const char* who, const LiteMath::float4x4& matrix);

// The ray interval [tnear, tfar] a query searches, or false when the ray must miss: NaN or inf
// in the origin, direction or tmin, a zero direction, or an empty interval (tmin >= tmax, also
// tmin == tmax). A negative tmin counts as 0, as in Embree and Vulkan; tmax = +inf is unbounded.
// Inline: BVHScene's traversal calls it, and the translator prints it for the GPU from here.
inline bool RayInterval(const LiteMath::float4& posAndNear, const LiteMath::float4& dirAndFar, float& tnear, float& tfar)
{
  tnear = std::max(posAndNear.w, 0.0f);
  tfar = dirAndFar.w;
  const bool finite = std::isfinite(posAndNear.x) && std::isfinite(posAndNear.y) && std::isfinite(posAndNear.z) &&
                      std::isfinite(posAndNear.w) && std::isfinite(dirAndFar.x) && std::isfinite(dirAndFar.y) &&
                      std::isfinite(dirAndFar.z);
  const bool nonZeroDir = dirAndFar.x != 0.0f || dirAndFar.y != 0.0f || dirAndFar.z != 0.0f;
  return finite && nonZeroDir && tnear < tfar;  // false for a NaN tfar too
}
}  // namespace litert_detail
