#include "SceneInput.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace litert_detail
{

void ValidateMesh(const char* who, const float* vpos3f, size_t vertNum, const uint32_t* triIndices, size_t indNum,
                  size_t vByteStride)
{
  const std::string prefix = std::string(who) + ": ";
  if (indNum % 3 != 0)
    throw std::invalid_argument(prefix + "index count " + std::to_string(indNum) + " is not a multiple of 3");
  if ((vertNum > 0 && vpos3f == nullptr) || (indNum > 0 && triIndices == nullptr))
    throw std::invalid_argument(prefix + "null vertex or index pointer with non-zero count");
  if (vByteStride < 3 * sizeof(float))
    throw std::invalid_argument(prefix + "vertex stride " + std::to_string(vByteStride) + " is less than 12 bytes");
  if (vertNum >= 0xFFFFFFFFull || indNum / 3 >= 0x7FFFFFFFull)
    throw std::invalid_argument(prefix + "mesh too large");
  for (size_t i = 0; i < indNum; i++)
    if (triIndices[i] >= vertNum)
      throw std::invalid_argument(prefix + "triangle index " + std::to_string(triIndices[i]) + " at position " +
                                  std::to_string(i) + " is out of range (vertNum = " + std::to_string(vertNum) + ")");
}

}  // namespace litert_detail
