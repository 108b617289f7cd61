// Floating-point arithmetic on the GPU as the C++ class computes it: every float add, subtract,
// multiply, divide and negate of a SPIR-V module gets the NoContraction decoration, so that no
// driver fuses a multiply and an add into one rounding where the CPU rounds twice.
//
// Why: GPU compilers contract a*b + c into an FMA by default, and the CPU build (x86-64 without
// -mfma) does not. Most code only moves in the last bits, but some algorithms depend on the
// two roundings: the watertight ray/triangle test computes each shared edge's function with
// the operands swapped on the two triangles, so that the results are exact negatives; fused,
// they are not, and rays leak between triangles. Morton codes, and with them LBVH trees, change.
// A class compiled with -ffp-contract=fast or -ffast-math allows contraction (Arguments.h).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace crossrt::engine {

// Decorates the result of every floating-point arithmetic instruction of `words` (a valid
// SPIR-V module) with NoContraction, unless it has it already. Returns how many it decorated.
size_t ForbidContraction(std::vector<uint32_t>& words);

}  // namespace crossrt::engine
