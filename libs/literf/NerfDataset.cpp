#include "NerfDataset.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace literf {

using LiteMath::float3;
using LiteMath::float4;

namespace {

std::string TransformsPath(const std::string& dir, const std::string& split) { return (std::filesystem::path(dir) / ("transforms_" + split + ".json")).string(); }

LiteMath::float4x4 Matrix(const nlohmann::json& m, const std::string& where)
{
  if (!m.is_array() || m.size() != 4)
    throw std::runtime_error(where + ": transform_matrix is not 4 rows of 4 numbers");
  float v[16];
  for (int r = 0; r < 4; ++r)
  {
    if (!m[r].is_array() || m[r].size() != 4)
      throw std::runtime_error(where + ": transform_matrix row " + std::to_string(r) + " is not 4 numbers");
    for (int c = 0; c < 4; ++c)
    {
      if (!m[r][c].is_number())
        throw std::runtime_error(where + ": transform_matrix[" + std::to_string(r) + "][" + std::to_string(c) + "] is not a number");
      v[4 * r + c] = m[r][c].get<float>();
    }
  }
  return LiteMath::float4x4(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11], v[12], v[13], v[14], v[15]);
}

}  // namespace

bool HasNerfSplit(const std::string& dir, const std::string& split) { return std::filesystem::exists(TransformsPath(dir, split)); }

NerfSplit LoadNerfSplit(const std::string& dir, const std::string& split, bool loadImages)
{
  const std::string path = TransformsPath(dir, split);
  std::ifstream in(path);
  if (!in)
    throw std::runtime_error(path + ": cannot open (a NeRF dataset folder holds transforms_train.json and transforms_test.json)");
  nlohmann::json doc;
  try
  {
    doc = nlohmann::json::parse(in);
  }
  catch (const nlohmann::json::parse_error& e)
  {
    throw std::runtime_error(path + ": malformed JSON: " + e.what());
  }
  NerfSplit out;
  if (!doc.is_object() || !doc.contains("camera_angle_x") || !doc["camera_angle_x"].is_number())
    throw std::runtime_error(path + ": no number camera_angle_x");
  out.cameraAngleX = doc["camera_angle_x"].get<float>();
  if (!(out.cameraAngleX > 0.0f && out.cameraAngleX < 3.14159f))
    throw std::runtime_error(path + ": camera_angle_x must lie in (0, pi), not " + std::to_string(out.cameraAngleX));
  if (!doc.contains("frames") || !doc["frames"].is_array() || doc["frames"].empty())
    throw std::runtime_error(path + ": no frames");
  const nlohmann::json& frames = doc["frames"];
  for (size_t i = 0; i < frames.size(); ++i)
  {
    const std::string where = path + ": frame " + std::to_string(i);
    const nlohmann::json& f = frames[i];
    if (!f.is_object() || !f.contains("file_path") || !f["file_path"].is_string())
      throw std::runtime_error(where + ": no file_path");
    if (!f.contains("transform_matrix"))
      throw std::runtime_error(where + ": no transform_matrix");
    NerfFrame frame;
    frame.filePath = f["file_path"].get<std::string>();
    frame.cameraToWorld = Matrix(f["transform_matrix"], where);
    if (loadImages)
    {
      std::string image = (std::filesystem::path(dir) / frame.filePath).lexically_normal().string();
      if (std::filesystem::path(image).extension() != ".png")
        image += ".png";
      LiteImage::Image2D<float4> rgba;
      if (!std::filesystem::exists(image) || !LiteImage::LoadImage(image.c_str(), rgba))
        throw std::runtime_error(where + ": cannot read the image " + image);
      if (out.frames.empty())
      {
        out.width = int(rgba.width());
        out.height = int(rgba.height());
      }
      else if (int(rgba.width()) != out.width || int(rgba.height()) != out.height)
        throw std::runtime_error(image + ": " + std::to_string(rgba.width()) + "x" + std::to_string(rgba.height()) + " pixels, but the split's first image has " +
                                 std::to_string(out.width) + "x" + std::to_string(out.height));
      frame.image = LiteImage::Image2D<float4>(rgba.width(), rgba.height());
      for (size_t p = 0; p < size_t(rgba.width()) * rgba.height(); ++p)
      {
        const float4 c = rgba.data()[p];
        frame.image.data()[p] = float4(c.x * c.w + 1.0f - c.w, c.y * c.w + 1.0f - c.w, c.z * c.w + 1.0f - c.w, 1.0f);
      }
    }
    out.frames.push_back(std::move(frame));
  }
  return out;
}

void SaveNerfSplit(const std::string& dir, const std::string& split, const NerfSplit& data)
{
  nlohmann::json doc;
  doc["camera_angle_x"] = data.cameraAngleX;
  doc["frames"] = nlohmann::json::array();
  for (const NerfFrame& f : data.frames)
  {
    nlohmann::json m = nlohmann::json::array();
    for (int r = 0; r < 4; ++r)
      m.push_back({f.cameraToWorld(r, 0), f.cameraToWorld(r, 1), f.cameraToWorld(r, 2), f.cameraToWorld(r, 3)});
    doc["frames"].push_back({{"file_path", f.filePath}, {"transform_matrix", m}});
    const std::filesystem::path image = std::filesystem::path(dir) / (f.filePath + ".png");
    std::filesystem::create_directories(image.parent_path());
    if (!LiteImage::SaveImage(image.lexically_normal().string().c_str(), f.image))
      throw std::runtime_error(image.string() + ": cannot write");
  }
  std::ofstream out(TransformsPath(dir, split));
  out << doc.dump(2) << "\n";
  if (!out)
    throw std::runtime_error(TransformsPath(dir, split) + ": cannot write");
}

}  // namespace literf
