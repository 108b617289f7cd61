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
  for (size_t i = 0; i < indNum; i++)
  {
    const float* v = reinterpret_cast<const float*>(reinterpret_cast<const char*>(vpos3f) + vByteStride * triIndices[i]);
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
      throw std::invalid_argument(prefix + "vertex " + std::to_string(triIndices[i]) + " (" + std::to_string(v[0]) + ", " +
                                  std::to_string(v[1]) + ", " + std::to_string(v[2]) + "), used by triangle " + std::to_string(i / 3) +
                                  ", is not finite");
  }
}

void ValidateInstanceMatrix(const char* who, const LiteMath::float4x4& matrix)
{
  for (int c = 0; c < 4; c++)
    for (int r = 0; r < 4; r++)
      if (!std::isfinite(matrix(r, c)))
        throw std::invalid_argument(std::string(who) + ": the instance matrix has a non-finite entry at row " + std::to_string(r) +
                                    ", column " + std::to_string(c));
  // The upper 3x3 part's determinant, in double: zero (or an inverse that overflows) is no placement.
  auto m = [&](int r, int c) { return double(matrix(r, c)); };
  const double det = m(0, 0) * (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1)) - m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0)) +
                     m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0));
  const LiteMath::float4x4 inverse = LiteMath::inverse4x4(matrix);
  bool finite = true;
  for (int c = 0; c < 4; c++)
    for (int r = 0; r < 4; r++)
      finite = finite && std::isfinite(inverse(r, c));
  if (det == 0.0 || !finite)
    throw std::invalid_argument(std::string(who) + ": the instance matrix is singular (determinant " + std::to_string(det) +
                                "): it has no inverse to move rays into the object's space");
}

}  // namespace litert_detail
