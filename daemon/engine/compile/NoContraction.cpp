// NoContraction on every floating-point arithmetic result of a SPIR-V module (see the header).
#include "compile/NoContraction.h"

#include <set>
#include <stdexcept>

namespace crossrt::engine {
namespace {

constexpr uint32_t kOpDecorate = 71;
constexpr uint32_t kNoContraction = 42;
constexpr size_t kHeaderWords = 5;

// Arithmetic whose result a driver could fuse with a neighbouring operation.
bool IsFloatArithmetic(uint32_t opcode) {
  switch (opcode) {
    case 127:  // OpFNegate
    case 129:  // OpFAdd
    case 131:  // OpFSub
    case 133:  // OpFMul
    case 136:  // OpFDiv
    case 142:  // OpVectorTimesScalar
    case 143:  // OpMatrixTimesScalar
    case 144:  // OpVectorTimesMatrix
    case 145:  // OpMatrixTimesVector
    case 146:  // OpMatrixTimesMatrix
    case 147:  // OpOuterProduct
    case 148:  // OpDot
      return true;
    default:
      return false;
  }
}

// The sections a module starts with, up to and including the annotations: the decorations go
// at their end, before the first type.
bool IsBeforeTypes(uint32_t opcode) {
  switch (opcode) {
    case 17: case 10: case 11: case 14: case 15: case 16: case 331:  // capabilities .. execution modes
    case 2: case 3: case 4: case 5: case 6: case 7: case 330:        // debug: sources, names, strings
    case 71: case 72: case 73: case 74: case 75: case 332: case 5632: case 5633:  // annotations
      return true;
    default:
      return false;
  }
}

}  // namespace

size_t ForbidContraction(std::vector<uint32_t>& words) {
  if (words.size() < kHeaderWords || words[0] != 0x07230203u)
    throw std::runtime_error("internal error: ForbidContraction was given something that is not SPIR-V");
  size_t insertAt = 0;
  std::set<uint32_t> decorated, arithmetic;
  for (size_t at = kHeaderWords; at < words.size();) {
    const uint32_t opcode = words[at] & 0xffffu, count = words[at] >> 16;
    if (count == 0 || at + count > words.size())
      throw std::runtime_error("internal error: a SPIR-V instruction runs past the end of its module");
    if (insertAt == 0 && !IsBeforeTypes(opcode)) insertAt = at;
    if (opcode == kOpDecorate && count >= 3 && words[at + 2] == kNoContraction) decorated.insert(words[at + 1]);
    if (IsFloatArithmetic(opcode) && count >= 3) arithmetic.insert(words[at + 2]);  // type, result, operands
    at += count;
  }
  if (insertAt == 0) insertAt = words.size();
  std::vector<uint32_t> decorations;
  for (uint32_t id : arithmetic) {
    if (decorated.count(id)) continue;
    decorations.insert(decorations.end(), {(3u << 16) | kOpDecorate, id, kNoContraction});
  }
  words.insert(words.begin() + std::ptrdiff_t(insertAt), decorations.begin(), decorations.end());
  return decorations.size() / 3;
}

}  // namespace crossrt::engine
