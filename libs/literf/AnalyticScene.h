// An analytic scene for training and benchmarks without a dataset: a sphere shaded by its normal
// and a box with a colour per face pair, opaque, on white, ray-cast exactly; cameras at distance 4
// on the upper hemisphere, looking at the origin, with the NeRF synthetic scenes' field of view.
#pragma once
#include "NerfDataset.h"

#include <cstdint>
#include <string>

namespace literf {

// The colour (alpha 1 on the objects, 0 on the white background) along the ray o + t d.
LiteMath::float4 AnalyticScenePixel(LiteMath::float3 o, LiteMath::float3 d);

// `views` frames of size x size named ./<split>/r_<i>, cameras drawn from `seed`.
NerfSplit MakeAnalyticSplit(const std::string& split, int views, int size, uint32_t seed);

}  // namespace literf
