// The NeRF synthetic ("Blender") dataset format: transforms_<split>.json holds camera_angle_x (the
// horizontal field of view, radians) and frames of file_path (relative, without ".png") and a 4x4
// camera-to-world transform_matrix (rows; the camera looks down -z with y up). Images are RGBA PNGs,
// composited over white as NeRF evaluations do. JSON through nlohmann::json, images through
// OpenImageIO (liteimage).
#pragma once
#include "Image2D.h"
#include "LiteMath.h"

#include <string>
#include <vector>

namespace literf {

struct NerfFrame
{
  std::string filePath;              // as transforms.json gives it: ./test/r_0
  LiteMath::float4x4 cameraToWorld;  // transform_matrix
  LiteImage::Image2D<LiteMath::float4> image;  // RGB over white, alpha 1 (empty without images)
};

struct NerfSplit
{
  float cameraAngleX = 0.0f;
  int width = 0, height = 0;  // of the first image (every image must match)
  std::vector<NerfFrame> frames;

  float Focal() const;  // in pixels: 0.5 * width / tan(0.5 * camera_angle_x)
};

// Reads DIR/transforms_<split>.json and, with loadImages, each frame's PNG. Throws
// std::runtime_error naming the file and what is wrong: missing, malformed JSON, a missing key or a
// matrix that is not 4x4, an image that cannot be read or differs in size from the first.
NerfSplit LoadNerfSplit(const std::string& dir, const std::string& split, bool loadImages = true);

// Whether DIR/transforms_<split>.json exists (val is optional in the format).
bool HasNerfSplit(const std::string& dir, const std::string& split);

// Writes a split: transforms_<split>.json and one PNG per frame (file_path + ".png", folders made),
// with the images' alpha as stored. For datasets made by programs.
void SaveNerfSplit(const std::string& dir, const std::string& split, const NerfSplit& data);

// The ray through the centre of pixel (x, y) of a frame: origin and unit direction.
void PixelRay(const LiteMath::float4x4& cameraToWorld, float focal, int width, int height, int x, int y, LiteMath::float3& origin,
              LiteMath::float3& direction);

// PSNR in dB of two RGB images of equal size (alpha ignored), values in [0, 1].
float Psnr(const LiteImage::Image2D<LiteMath::float4>& a, const LiteImage::Image2D<LiteMath::float4>& b);

}  // namespace literf
