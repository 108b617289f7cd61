#include "SphericalHarmonics.h"

#include <cmath>

using LiteMath::float3;

void SphericalHarmonics::Project(const uint32_t* a_data, uint32_t a_width, uint32_t a_height)
{
  kernel2D_Project(a_data, a_width, a_height);
}

void SphericalHarmonics::kernel2D_Project(const uint32_t* a_data, uint32_t a_width, uint32_t a_height)
{
  coefs[0] = coefs[1] = coefs[2] = float3(0.0f);
  coefs[3] = coefs[4] = coefs[5] = float3(0.0f);
  coefs[6] = coefs[7] = coefs[8] = float3(0.0f);
  m_texels = 0;
  for (uint32_t i = 0; i < a_height; ++i)
  {
    for (uint32_t j = 0; j < a_width; ++j)
    {
      const float  phi       = (float(i) + 0.5f) / float(a_height) * 2.0f * PI;
      const float  theta     = 2.0f * std::acos(std::sqrt(1.0f - (float(j) + 0.5f) / float(a_width)));
      const float3 d         = float3(std::cos(phi) * std::sin(theta), std::sin(phi) * std::sin(theta), std::cos(theta));
      const uint32_t texel   = a_data[i * a_width + j];
      const float3 color     = float3(float(texel & 0xFF), float((texel >> 8) & 0xFF), float((texel >> 16) & 0xFF)) / 255.0f;
      coefs[0] += color;
      coefs[1] += color * d.y;
      coefs[2] += color * d.z;
      coefs[3] += color * d.x;
      coefs[4] += color * d.x * d.y;
      coefs[5] += color * d.y * d.z;
      coefs[6] += color * (2.0f * d.z * d.z - d.x * d.x - d.y * d.y);
      coefs[7] += color * d.x * d.z;
      coefs[8] += color * (d.x * d.x - d.y * d.y);
      m_texels += int(kOneTexel);
    }
  }
  const float norm = 4.0f * PI / float(a_width * a_height);
  for (int k = 0; k < kCoefficients; ++k)
    coefs[k] *= norm;
}
