// Signed distance fields in Embree: a user geometry whose primitives are a sparse voxel set's
// voxels, a sparse brick set's bricks, or a dense grid (one primitive), intersected by litesdf's own
// leaf tests (SdfLeaves.h). The CPU reference for BVHScene's SDF leaves, which read the same values
// packed for the GPU: the two are written apart, so tests comparing them compare two implementations.
#pragma once
#include <embree3/rtcore.h>

#include <memory>

namespace litesdf {
struct SdfGrid;
struct SdfSVS;
struct SdfSBS;
}  // namespace litesdf

namespace litert_detail {

// A committed user geometry holding a copy of the field; `keepAlive` owns what Embree's callbacks read
// and must live as long as the geometry.
RTCGeometry NewSdfGeometry(RTCDevice device, const litesdf::SdfGrid& grid, std::shared_ptr<void>& keepAlive);
RTCGeometry NewSdfGeometry(RTCDevice device, const litesdf::SdfSVS& svs, std::shared_ptr<void>& keepAlive);
RTCGeometry NewSdfGeometry(RTCDevice device, const litesdf::SdfSBS& sbs, std::shared_ptr<void>& keepAlive);

}  // namespace litert_detail
