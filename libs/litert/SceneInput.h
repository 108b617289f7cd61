// Input rules every ISceneObject implementation in litert applies the same way.
#pragma once
#include "LiteMath.h"

#include <cstddef>
#include <cstdint>

namespace litert_detail
{
// Throws std::invalid_argument (message prefixed by `who`) for a mesh that would be read out of
// bounds: an index count not a multiple of 3, null data, a short stride, an index >= vertNum.
void ValidateMesh(const char* who, const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum,
                  size_t vByteStride);

// The ray interval [tnear, tfar] a query searches, or false when the ray must miss: NaN or inf
// in the origin, direction or tmin, a zero direction, or an empty interval (tmin >= tmax, also
// tmin == tmax). A negative tmin counts as 0, as in Embree and Vulkan; tmax = +inf is unbounded.
bool RayInterval(const LiteMath::float4& posAndNear, const LiteMath::float4& dirAndFar, float& tnear, float& tfar);
}  // namespace litert_detail
