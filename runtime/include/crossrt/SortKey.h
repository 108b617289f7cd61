// How a std::sort the translator recognized orders its elements; shared by the GPU and CPU sorts.
#pragma once
#include <cstdint>

namespace crossrt {

// The 32-bit element types scans and sort keys come in.
enum class ElementType : uint32_t { Uint = 0, Int = 1, Float = 2 };

// What std::sort compares: records of `strideWords` 32-bit words, ordered by the word at
// `keyWord` read as `type`, ascending or descending. Plain keys are records of one word.
struct SortKey {
  uint32_t strideWords = 1;
  uint32_t keyWord = 0;
  ElementType type = ElementType::Uint;
  bool descending = false;
};

// A key's bits as a uint whose unsigned order is the requested order (the GPU shaders do the same).
inline uint32_t SortableBits(uint32_t bits, const SortKey& key) {
  if (key.type == ElementType::Int)
    bits ^= 0x80000000u;  // the sign bit decides first
  else if (key.type == ElementType::Float) {
    if (bits == 0x80000000u) bits = 0u;  // -0.0f sorts with +0.0f, as std::sort's comparator sees them equal
    bits = (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);  // negative floats in reverse
  }
  return key.descending ? ~bits : bits;
}

}  // namespace crossrt
