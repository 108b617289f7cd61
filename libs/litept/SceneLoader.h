// Scenes for the path tracer (libs/litept), read through libraries: glTF 2.0 (.gltf, .glb) with
// tinygltf, OBJ with MTL through assimp. A PathScene is plain host data: meshes, their instances,
// materials and punctual lights as the objects the integrator will hold, textures, a camera and an
// optional environment map. PathTracer::SetScene copies it to the integrator.
//
// glTF: the default scene's node hierarchy (matrices or TRS), each mesh once with an instance per
// node that uses it, perspective cameras, metallic-roughness materials with their textures, and the
// extensions KHR_materials_emissive_strength, KHR_materials_transmission with KHR_materials_ior,
// KHR_materials_specular (its factor) and KHR_lights_punctual. glTF has no area lights: a point
// light whose "extras" give a "radius" is a sphere light, one with "width" and "height" a rectangle
// in its node's xy plane facing -z; either has the point light's intensity along its axis (radiance
// = intensity / (pi r^2), or intensity / area). PathScene::lights takes SphereLight and RectLight
// directly too. A scene without a camera or any light gets a stated default (`notes`), as does
// anything read only approximately.
#pragma once
#include "Image2D.h"
#include "Lights.h"
#include "LiteMath.h"
#include "Materials.h"

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

// A scene file that cannot be read: the message names the file and what is wrong.
struct SceneError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

struct PathScene
{
  struct Mesh
  {
    std::string name;
    std::vector<LiteMath::float4> positions, normals, tangents;  // per vertex, object space (tangent w: the bitangent's sign)
    std::vector<LiteMath::float2> texcoords;
    std::vector<uint32_t> indices;           // three per triangle
    std::vector<uint32_t> triangleMaterial;  // per triangle, into materials
  };
  struct Instance
  {
    uint32_t mesh;
    LiteMath::float4x4 toWorld;
  };
  struct Camera
  {
    LiteMath::float3 position{0.0f, 0.0f, 0.0f};
    LiteMath::float3 forward{0.0f, 0.0f, -1.0f};
    LiteMath::float3 up{0.0f, 1.0f, 0.0f};
    float yfov = 0.6911112f;  // radians
    float aspect = 0.0f;      // 0: the image's
    float lensRadius = 0.0f;
    float focusDistance = 1.0f;
  };

  std::vector<Mesh> meshes;
  std::vector<Instance> instances;
  std::vector<std::shared_ptr<litept::IMaterial>> materials;
  std::vector<std::string> materialNames;
  std::vector<LiteImage::Texture2D<LiteMath::float4>> textures;  // linear
  std::vector<std::shared_ptr<litept::ILight>> lights;            // punctual lights; emissive triangles come from the materials
  Camera camera;
  bool hasCamera = false;
  LiteImage::Image2D<LiteMath::float4> environment;  // equirectangular, linear, strength applied; empty: none
  std::vector<std::string> notes;  // defaults taken and approximations made, for the user
};

// Reads a .gltf, .glb or .obj file. Throws SceneError naming the file and the problem.
PathScene LoadScene(const std::string& path);

// Reads an equirectangular environment map (EXR, HDR, ...) into scene.environment. Throws SceneError.
void LoadEnvironment(PathScene& scene, const std::string& path, float strength = 1.0f);

// Fills in what the scene lacks, with a note each: a camera framing the scene (yfov 0.6911 rad,
// looking down -z from the bounding sphere's centre + (0, 0, r / sin(yfov / 2))) and, when nothing
// emits light, a uniform white environment of radiance 1.
void ApplySceneDefaults(PathScene& scene);

// The scene's world-space bounding box (over all instances' vertices).
void SceneBounds(const PathScene& scene, LiteMath::float3& boxMin, LiteMath::float3& boxMax);
