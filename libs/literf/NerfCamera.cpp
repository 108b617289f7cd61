// The camera side of the NeRF format and the analytic scene (see the headers): no files, so a
// program that only uses these does not link the image readers.
#include "AnalyticScene.h"
#include "NerfDataset.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace literf {

using LiteMath::float3;
using LiteMath::float4;

float NerfSplit::Focal() const { return 0.5f * float(width) / std::tan(0.5f * cameraAngleX); }

void PixelRay(const LiteMath::float4x4& cameraToWorld, float focal, int width, int height, int x, int y, float3& origin, float3& direction)
{
  const float4 d = cameraToWorld.get_col(0) * ((float(x) + 0.5f - 0.5f * float(width)) / focal) -
                   cameraToWorld.get_col(1) * ((float(y) + 0.5f - 0.5f * float(height)) / focal) - cameraToWorld.get_col(2);
  const float4 o = cameraToWorld.get_col(3);
  origin = float3(o.x, o.y, o.z);
  direction = LiteMath::normalize(float3(d.x, d.y, d.z));
}

float Psnr(const LiteImage::Image2D<float4>& a, const LiteImage::Image2D<float4>& b)
{
  if (a.width() != b.width() || a.height() != b.height() || a.width() == 0)
    throw std::runtime_error("PSNR of images of different sizes");
  double sum = 0.0;
  const size_t n = size_t(a.width()) * a.height();
  for (size_t i = 0; i < n; ++i)
  {
    const float4 d = a.data()[i] - b.data()[i];
    sum += double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z;
  }
  const double mse = sum / (3.0 * double(n));
  return mse > 0.0 ? float(-10.0 * std::log10(mse)) : 99.0f;
}

float4 AnalyticScenePixel(float3 o, float3 d)
{
  float best = 1e30f;
  float4 colour = float4(1.0f, 1.0f, 1.0f, 0.0f);
  const float3 c = float3(-0.3f, 0.0f, 0.0f);
  const float b = LiteMath::dot(o - c, d), disc = b * b - (LiteMath::dot(o - c, o - c) - 0.49f);
  if (disc >= 0.0f && -b - std::sqrt(disc) > 0.0f)
  {
    best = -b - std::sqrt(disc);
    const float3 n = LiteMath::normalize(o + d * best - c);
    colour = float4(0.5f + 0.4f * n.x, 0.5f + 0.4f * n.y, 0.5f + 0.4f * n.z, 1.0f);
  }
  const float3 lo = float3(0.3f, -0.6f, -0.4f), hi = float3(0.9f, 0.2f, 0.4f);
  float enter = 0.0f, leave = 1e30f;
  int axis = 0;
  for (int k = 0; k < 3; ++k)
  {
    const float t0 = (lo[k] - o[k]) / d[k], t1 = (hi[k] - o[k]) / d[k];
    if (std::min(t0, t1) > enter)
    {
      enter = std::min(t0, t1);
      axis = k;
    }
    leave = std::min(leave, std::max(t0, t1));
  }
  if (enter < leave && enter > 0.0f && enter < best)
    colour = axis == 0 ? float4(0.9f, 0.3f, 0.2f, 1.0f) : axis == 1 ? float4(0.9f, 0.8f, 0.2f, 1.0f) : float4(0.3f, 0.4f, 0.9f, 1.0f);
  return colour;
}

NerfSplit MakeAnalyticSplit(const std::string& split, int views, int size, uint32_t seed)
{
  if (size < 1 || views < 0)
    throw std::runtime_error("an analytic split needs a positive image size");
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  NerfSplit s;
  s.cameraAngleX = 0.6911f;  // the NeRF synthetic scenes'
  s.width = s.height = size;
  for (int v = 0; v < views; ++v)
  {
    const float phi = 6.2831853f * u(rng), z = 0.1f + 0.85f * u(rng), r = std::sqrt(1.0f - z * z);
    const float3 eye = float3(r * std::cos(phi), z, r * std::sin(phi)) * 4.0f;
    const float3 back = LiteMath::normalize(eye), right = LiteMath::normalize(LiteMath::cross(float3(0.0f, 1.0f, 0.0f), back));
    const float3 up = LiteMath::cross(back, right);
    NerfFrame f;
    f.filePath = "./" + split + "/r_" + std::to_string(v);
    f.cameraToWorld = LiteMath::float4x4(right.x, up.x, back.x, eye.x, right.y, up.y, back.y, eye.y, right.z, up.z, back.z, eye.z, 0.0f, 0.0f, 0.0f, 1.0f);
    f.image = LiteImage::Image2D<float4>(uint32_t(size), uint32_t(size));
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x)
      {
        float3 o, d;
        PixelRay(f.cameraToWorld, s.Focal(), size, size, x, y, o, d);
        f.image.data()[y * size + x] = AnalyticScenePixel(o, d);
      }
    s.frames.push_back(std::move(f));
  }
  return s;
}

}  // namespace literf
