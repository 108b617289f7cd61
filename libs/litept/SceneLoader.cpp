// Reads glTF 2.0 (tinygltf) and OBJ with MTL (assimp) into a PathScene (SceneLoader.h).
#include "SceneLoader.h"

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#define TINYGLTF_NO_STB_IMAGE  // as TinyGltf.cpp compiles it
#define TINYGLTF_NO_STB_IMAGE_WRITE
#include <tiny_gltf.h>
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>

using namespace LiteMath;

namespace {

constexpr float kLumensPerWatt = 683.0f;  // glTF's photometric units to the radiometric ones, as Blender's importer converts them

std::string Lower(std::string s)
{
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

float SrgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

float3 TransformPoint(const float4x4& m, float3 p) { return to_float3(m * float4(p.x, p.y, p.z, 1.0f)); }
float3 TransformVector(const float4x4& m, float3 v) { return to_float3(m * float4(v.x, v.y, v.z, 0.0f)); }

// Flat normals where a mesh has none (glTF's rule): every triangle gets its own three vertices.
void MakeFlat(PathScene::Mesh& mesh)
{
  PathScene::Mesh flat;
  flat.name = mesh.name;
  flat.triangleMaterial = mesh.triangleMaterial;
  const bool uvs = !mesh.texcoords.empty();
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
  {
    const float3 a = to_float3(mesh.positions[mesh.indices[t]]), b = to_float3(mesh.positions[mesh.indices[t + 1]]),
                 c = to_float3(mesh.positions[mesh.indices[t + 2]]);
    float3 n = cross(b - a, c - a);
    const float len = length(n);
    n = len > 0.0f ? n * (1.0f / len) : float3(0.0f, 0.0f, 1.0f);
    for (int k = 0; k < 3; ++k)
    {
      flat.indices.push_back(uint32_t(flat.positions.size()));
      flat.positions.push_back(mesh.positions[mesh.indices[t + k]]);
      flat.normals.push_back(to_float4(n, 0.0f));
      if (uvs)
        flat.texcoords.push_back(mesh.texcoords[mesh.indices[t + k]]);
    }
  }
  mesh = std::move(flat);
}

// Per-vertex tangents from the texture coordinates (for normal maps), orthogonalised against the normal,
// for meshes without glTF TANGENT.
void ComputeTangents(PathScene::Mesh& mesh)
{
  std::vector<float3> tan(mesh.positions.size(), float3(0.0f)), bitan(mesh.positions.size(), float3(0.0f));
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
  {
    const uint32_t i0 = mesh.indices[t], i1 = mesh.indices[t + 1], i2 = mesh.indices[t + 2];
    const float3 e1 = to_float3(mesh.positions[i1] - mesh.positions[i0]), e2 = to_float3(mesh.positions[i2] - mesh.positions[i0]);
    const float2 d1 = mesh.texcoords[i1] - mesh.texcoords[i0], d2 = mesh.texcoords[i2] - mesh.texcoords[i0];
    const float det = d1.x * d2.y - d2.x * d1.y;
    if (std::fabs(det) < 1e-12f)
      continue;
    const float r = 1.0f / det;
    const float3 sdir = (e1 * d2.y - e2 * d1.y) * r, tdir = (e2 * d1.x - e1 * d2.x) * r;
    for (uint32_t i : {i0, i1, i2})
      tan[i] += sdir, bitan[i] += tdir;
  }
  mesh.tangents.resize(mesh.positions.size());
  for (size_t i = 0; i < mesh.positions.size(); ++i)
  {
    const float3 n = to_float3(mesh.normals[i]);
    float3 t = tan[i] - n * dot(n, tan[i]);
    if (dot(t, t) < 1e-20f)
    {
      float3 b;
      litept::BranchlessOnb(n, t, b);
    }
    t = normalize(t);
    // A normal map's green axis points up the image, and glTF's v runs down it: the bitangent
    // (cross(n, t) * w, as glTF defines it) is -dP/dv.
    const float w = dot(cross(n, t), bitan[i]) < 0.0f ? 1.0f : -1.0f;
    mesh.tangents[i] = to_float4(t, w);
  }
}

// ---------------------------------------------------------------- glTF

// tinygltf's image loader: PNG, JPEG (or anything OpenImageIO reads) from the bytes tinygltf found
// in a file, a buffer view or a data URI, as 8 or 16 bits per channel.
bool DecodeGltfImage(tinygltf::Image* image, const int index, std::string* err, std::string* warn, int reqWidth, int reqHeight,
                     const unsigned char* bytes, int size, void* user)
{
  (void)warn, (void)reqWidth, (void)reqHeight, (void)user;
  OIIO::Filesystem::IOMemReader memory(bytes, size_t(size));
  // OpenImageIO picks the reader by the name's extension: the image's type, from its first bytes.
  const bool png = size > 4 && bytes[0] == 0x89 && bytes[1] == 'P';
  const bool jpeg = size > 2 && bytes[0] == 0xFF && bytes[1] == 0xD8;
  const std::string name = png ? "image.png" : jpeg ? "image.jpg" : image->uri.empty() ? "image.png" : image->uri;
  // The memory goes to the reader as the configuration's "oiio:ioproxy": handed over as open()'s
  // third argument instead, OpenImageIO 2.4's PNG reader still looks for a file of that name.
  OIIO::ImageSpec config;
  void* proxy = &memory;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  auto in = OIIO::ImageInput::open(name, &config);
  if (!in)
  {
    if (err)
      *err += "image " + std::to_string(index) + " ('" + image->uri + "'): " + OIIO::geterror() + "\n";
    return false;
  }
  const OIIO::ImageSpec& spec = in->spec();
  const bool wide = spec.format.size() > 1;
  image->width = spec.width;
  image->height = spec.height;
  image->component = spec.nchannels;
  image->bits = wide ? 16 : 8;
  image->pixel_type = wide ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  image->image.resize(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels) * (wide ? 2u : 1u));
  if (!in->read_image(0, 0, 0, spec.nchannels, wide ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8, image->image.data()))
  {
    if (err)
      *err += "image " + std::to_string(index) + " ('" + image->uri + "'): " + in->geterror() + "\n";
    return false;
  }
  return true;
}

class GltfReader
{
public:
  GltfReader(const std::string& path, PathScene& scene) : m_path(path), m_scene(scene) {}

  void Read()
  {
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(DecodeGltfImage, nullptr);
    std::string err, warn;
    const bool binary = Lower(std::filesystem::path(m_path).extension().string()) == ".glb";
    const bool ok = binary ? loader.LoadBinaryFromFile(&m_model, &err, &warn, m_path) : loader.LoadASCIIFromFile(&m_model, &err, &warn, m_path);
    if (!ok || !err.empty())
      throw SceneError(m_path + ": error: not a readable glTF 2.0 file: " + (err.empty() ? std::string("unknown error") : err));
    if (!warn.empty())
      m_scene.notes.push_back(m_path + ": tinygltf: " + warn);
    for (size_t i = 0; i < m_model.materials.size(); ++i)
      ReadMaterial(m_model.materials[i]);
    m_defaultMaterial = uint32_t(m_scene.materials.size());  // for primitives without one: glTF's default (white, metallic 1, roughness 1)
    m_scene.materials.push_back(std::make_shared<litept::GltfMetalRough>());
    m_scene.materialNames.push_back("(glTF default material)");
    m_meshOf.assign(m_model.meshes.size(), -1);
    const int sceneIndex = m_model.defaultScene >= 0 ? m_model.defaultScene : 0;
    if (m_model.scenes.empty())
    {
      for (size_t n = 0; n < m_model.nodes.size(); ++n)  // no scenes: every root node
        if (!IsChild(int(n)))
          Visit(int(n), float4x4(), 0);
    }
    else
    {
      if (sceneIndex >= int(m_model.scenes.size()))
        throw SceneError(m_path + ": error: the default scene " + std::to_string(sceneIndex) + " does not exist");
      for (int n : m_model.scenes[sceneIndex].nodes)
        Visit(n, float4x4(), 0);
    }
  }

private:
  bool IsChild(int node) const
  {
    for (const auto& n : m_model.nodes)
      if (std::find(n.children.begin(), n.children.end(), node) != n.children.end())
        return true;
    return false;
  }

  static float4x4 NodeMatrix(const tinygltf::Node& node)
  {
    float4x4 m;
    if (node.matrix.size() == 16)
    {
      for (int c = 0; c < 4; ++c)
        m.set_col(c, float4(float(node.matrix[4 * c]), float(node.matrix[4 * c + 1]), float(node.matrix[4 * c + 2]), float(node.matrix[4 * c + 3])));
      return m;
    }
    float4x4 t, r, s;
    if (node.translation.size() == 3)
      t = translate4x4(float3(float(node.translation[0]), float(node.translation[1]), float(node.translation[2])));
    if (node.rotation.size() == 4)
    {
      const float x = float(node.rotation[0]), y = float(node.rotation[1]), z = float(node.rotation[2]), w = float(node.rotation[3]);
      r.set_col(0, float4(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w), 0));
      r.set_col(1, float4(2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w), 0));
      r.set_col(2, float4(2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y), 0));
    }
    if (node.scale.size() == 3)
      s = scale4x4(float3(float(node.scale[0]), float(node.scale[1]), float(node.scale[2])));
    return t * r * s;
  }

  void Visit(int nodeIndex, const float4x4& parent, int depth)
  {
    if (nodeIndex < 0 || nodeIndex >= int(m_model.nodes.size()) || depth > 64)
      throw SceneError(m_path + ": error: node " + std::to_string(nodeIndex) + (depth > 64 ? " is part of a cycle" : " does not exist"));
    const tinygltf::Node& node = m_model.nodes[nodeIndex];
    const float4x4 world = parent * NodeMatrix(node);
    if (node.mesh >= 0)
    {
      if (node.mesh >= int(m_model.meshes.size()))
        throw SceneError(m_path + ": error: node " + std::to_string(nodeIndex) + " names mesh " + std::to_string(node.mesh) + ", which does not exist");
      if (m_meshOf[node.mesh] < 0)
        m_meshOf[node.mesh] = ReadMesh(m_model.meshes[node.mesh]);
      if (m_meshOf[node.mesh] < int(m_scene.meshes.size()) && !m_scene.meshes[m_meshOf[node.mesh]].indices.empty())
        m_scene.instances.push_back({uint32_t(m_meshOf[node.mesh]), world});
    }
    if (node.camera >= 0 && node.camera < int(m_model.cameras.size()) && !m_scene.hasCamera)
      ReadCamera(m_model.cameras[node.camera], world);
    const auto lightExt = node.extensions.find("KHR_lights_punctual");
    if (lightExt != node.extensions.end() && lightExt->second.Has("light"))
      ReadLight(lightExt->second.Get("light").GetNumberAsInt(), world);
    for (int child : node.children)
      Visit(child, world, depth + 1);
  }

  void ReadCamera(const tinygltf::Camera& camera, const float4x4& world)
  {
    if (camera.type != "perspective")
    {
      m_scene.notes.push_back(m_path + ": the " + camera.type + " camera is skipped: only perspective cameras are read");
      return;
    }
    PathScene::Camera& c = m_scene.camera;
    c.position = TransformPoint(world, float3(0.0f));
    c.forward = normalize(TransformVector(world, float3(0.0f, 0.0f, -1.0f)));
    c.up = normalize(TransformVector(world, float3(0.0f, 1.0f, 0.0f)));
    c.yfov = float(camera.perspective.yfov);
    c.aspect = float(camera.perspective.aspectRatio);
    m_scene.hasCamera = true;
  }

  void ReadLight(int index, const float4x4& world)
  {
    if (index < 0 || index >= int(m_model.lights.size()))
      throw SceneError(m_path + ": error: KHR_lights_punctual light " + std::to_string(index) + " does not exist");
    const tinygltf::Light& l = m_model.lights[index];
    float3 color(1.0f);
    if (l.color.size() == 3)
      color = float3(float(l.color[0]), float(l.color[1]), float(l.color[2]));
    const float3 value = color * (float(l.intensity) / kLumensPerWatt);
    const float3 position = TransformPoint(world, float3(0.0f));
    const float3 direction = normalize(TransformVector(world, float3(0.0f, 0.0f, -1.0f)));
    // A point light with a size in its "extras" is a sphere ("radius") or a rectangle ("width" and
    // "height", in the node's xy plane, facing -z) of the same intensity along its axis.
    auto extra = [&](const char* field) {
      return l.extras.IsObject() && l.extras.Has(field) && l.extras.Get(field).IsNumber() ? l.extras.Get(field).GetNumberAsDouble() : 0.0;
    };
    const float radius = float(extra("radius")), width = float(extra("width")), height = float(extra("height"));
    if (l.type == "point" && radius > 0.0f)
    {
      auto sphere = std::make_shared<litept::SphereLight>();
      sphere->centerRadius = to_float4(position, radius);
      sphere->radiance = to_float4(value * (1.0f / (litept::kPi * radius * radius)), 0.0f);
      m_scene.lights.push_back(sphere);
    }
    else if (l.type == "point" && width > 0.0f && height > 0.0f)
    {
      const float3 x = normalize(TransformVector(world, float3(1.0f, 0.0f, 0.0f))), y = normalize(TransformVector(world, float3(0.0f, 1.0f, 0.0f)));
      auto rect = std::make_shared<litept::RectLight>();
      rect->corner = to_float4(position - x * (0.5f * width) - y * (0.5f * height), 1.0f);
      rect->edge1 = to_float4(y * height, 0.0f);  // cross(y, x) = -z: it faces the way the node looks
      rect->edge2 = to_float4(x * width, 0.0f);
      rect->radiance = to_float4(value * (1.0f / (width * height)), 0.0f);
      m_scene.lights.push_back(rect);
    }
    else if (l.type == "point")
    {
      auto p = std::make_shared<litept::PointLight>();
      p->position = to_float4(position, 1.0f);
      p->intensity = to_float4(value, 0.0f);
      m_scene.lights.push_back(p);
    }
    else if (l.type == "spot")
    {
      auto s = std::make_shared<litept::SpotLight>();
      s->position = to_float4(position, 1.0f);
      s->direction = to_float4(direction, 0.0f);
      s->intensity = to_float4(value, 0.0f);
      s->cosInner = std::cos(float(l.spot.innerConeAngle));
      s->cosOuter = std::cos(float(l.spot.outerConeAngle));
      m_scene.lights.push_back(s);
    }
    else if (l.type == "directional")
    {
      auto d = std::make_shared<litept::DirectionalLight>();
      d->direction = to_float4(direction, 0.0f);
      d->irradiance = to_float4(value, 0.0f);
      m_scene.lights.push_back(d);
    }
    else
      throw SceneError(m_path + ": error: light " + std::to_string(index) + " has the unknown type '" + l.type + "'");
    if (l.range > 0.0)
      m_scene.notes.push_back(m_path + ": light " + std::to_string(index) + "'s range is ignored (lights fall off with the inverse square law only)");
  }

  // A texture as linear float4 texels, converted from sRGB where it holds colours; cached.
  int Texture(int textureIndex, bool srgb, const std::string& material)
  {
    if (textureIndex < 0)
      return -1;
    if (textureIndex >= int(m_model.textures.size()))
      throw SceneError(m_path + ": error: material '" + material + "' names texture " + std::to_string(textureIndex) + ", which does not exist");
    const auto key = std::make_pair(textureIndex, srgb);
    const auto cached = m_textureOf.find(key);
    if (cached != m_textureOf.end())
      return cached->second;
    const tinygltf::Texture& tex = m_model.textures[textureIndex];
    if (tex.source < 0 || tex.source >= int(m_model.images.size()))
      throw SceneError(m_path + ": error: texture " + std::to_string(textureIndex) + " has no image");
    const tinygltf::Image& img = m_model.images[tex.source];
    if (img.width <= 0 || img.height <= 0 || img.image.empty())
      throw SceneError(m_path + ": error: texture image '" + (img.uri.empty() ? img.name : img.uri) + "' could not be read");
    LiteImage::Image2D<float4> image(uint32_t(img.width), uint32_t(img.height));
    const int comps = img.component;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x)
      {
        float v[4] = {0.0f, 0.0f, 0.0f, 1.0f};
        for (int c = 0; c < comps && c < 4; ++c)
        {
          const size_t at = (size_t(y) * size_t(img.width) + size_t(x)) * size_t(comps) + size_t(c);
          v[c] = img.bits == 16 ? float(reinterpret_cast<const uint16_t*>(img.image.data())[at]) / 65535.0f : float(img.image[at]) / 255.0f;
        }
        if (comps < 3)  // grey (and alpha)
        {
          v[3] = comps == 2 ? v[1] : 1.0f;
          v[1] = v[2] = v[0];
        }
        if (srgb)
          for (int c = 0; c < 3; ++c)
            v[c] = SrgbToLinear(v[c]);
        image[int2(x, y)] = float4(v[0], v[1], v[2], v[3]);
      }
    LiteImage::Sampler sampler;
    sampler.filter = LiteImage::Sampler::Filter::LINEAR;
    if (tex.sampler >= 0 && tex.sampler < int(m_model.samplers.size()))
    {
      const tinygltf::Sampler& s = m_model.samplers[tex.sampler];
      auto mode = [](int wrap) {
        return wrap == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE      ? LiteImage::Sampler::AddressMode::CLAMP
               : wrap == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? LiteImage::Sampler::AddressMode::MIRROR
                                                               : LiteImage::Sampler::AddressMode::WRAP;
      };
      sampler.addressU = mode(s.wrapS);
      sampler.addressV = mode(s.wrapT);
      if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST)
        sampler.filter = LiteImage::Sampler::Filter::NEAREST;
    }
    const int id = int(m_scene.textures.size());
    m_scene.textures.emplace_back(std::move(image), sampler);
    m_textureOf[key] = id;
    return id;
  }

  static double Number(const tinygltf::ExtensionMap& ext, const char* name, const char* field, double fallback)
  {
    const auto e = ext.find(name);
    if (e == ext.end() || !e->second.Has(field))
      return fallback;
    return e->second.Get(field).GetNumberAsDouble();
  }

  void ReadMaterial(const tinygltf::Material& m)
  {
    const std::string name = m.name.empty() ? "material " + std::to_string(m_scene.materials.size()) : m.name;
    const auto& pbr = m.pbrMetallicRoughness;
    const float4 base(float(pbr.baseColorFactor[0]), float(pbr.baseColorFactor[1]), float(pbr.baseColorFactor[2]), float(pbr.baseColorFactor[3]));
    const float strength = float(Number(m.extensions, "KHR_materials_emissive_strength", "emissiveStrength", 1.0));
    const float3 emission = float3(float(m.emissiveFactor[0]), float(m.emissiveFactor[1]), float(m.emissiveFactor[2])) * strength;
    const float4 emission4 = to_float4(emission, m.doubleSided ? 1.0f : 0.0f);
    const float transmission = float(Number(m.extensions, "KHR_materials_transmission", "transmissionFactor", 0.0));
    const float ior = float(Number(m.extensions, "KHR_materials_ior", "ior", 1.5));
    const float specular = float(Number(m.extensions, "KHR_materials_specular", "specularFactor", 1.0));
    const float roughness = float(pbr.roughnessFactor), metallic = float(pbr.metallicFactor);
    const int baseTex = Texture(pbr.baseColorTexture.index, true, name);
    const int mrTex = Texture(pbr.metallicRoughnessTexture.index, false, name);
    const int normalTex = Texture(m.normalTexture.index, false, name);
    const int emissiveTex = Texture(m.emissiveTexture.index, true, name);
    for (const auto& extension : m.extensions)  // what the materials here do not model, said once per material
      if (extension.first != "KHR_materials_emissive_strength" && extension.first != "KHR_materials_transmission" &&
          extension.first != "KHR_materials_ior" && extension.first != "KHR_materials_specular")
        m_scene.notes.push_back(m_path + ": material '" + name + "': " + extension.first + " is ignored");
    if (m.alphaMode != "OPAQUE" && base.w < 1.0f)
      m_scene.notes.push_back(m_path + ": material '" + name + "': alpha (" + m.alphaMode + ") is ignored: the surface is opaque");
    if (transmission > 0.0f && metallic < 1.0f)
    {
      // Glass: a dielectric with the base colour as its tint.
      auto d = std::make_shared<litept::Dielectric>();
      d->tint = to_float4(to_float3(base), 0.0f);
      d->ior = ior;
      d->alpha = roughness * roughness;
      if (transmission < 1.0f || metallic > 0.0f || baseTex >= 0)
        m_scene.notes.push_back(m_path + ": material '" + name + "': transmission " + std::to_string(transmission) +
                                " is rendered as full transmission (no metal, no textures)");
      m_scene.materials.push_back(d);
    }
    else if (metallic == 0.0f && specular == 0.0f && mrTex < 0 && normalTex < 0)
    {
      // No specular layer left (KHR_materials_specular's factor 0): Lambert.
      auto l = std::make_shared<litept::Lambert>();
      l->albedo = to_float4(to_float3(base), 0.0f);
      l->emission = emission4;
      l->baseColorTexture = baseTex;
      l->emissiveTexture = emissiveTex;
      m_scene.materials.push_back(l);
    }
    else
    {
      auto g = std::make_shared<litept::GltfMetalRough>();
      g->baseColor = base;
      g->emission = emission4;
      g->metallic = metallic;
      g->roughness = roughness;
      const float f0 = (ior - 1.0f) / (ior + 1.0f);
      g->specularF0 = f0 * f0 * specular;
      g->baseColorTexture = baseTex;
      g->metallicRoughnessTexture = mrTex;
      g->normalTexture = normalTex;
      g->emissiveTexture = emissiveTex;
      m_scene.materials.push_back(g);
    }
    m_scene.materialNames.push_back(name);
  }

  // An accessor's elements as floats, `width` per element (normalised integers scaled to [0, 1]).
  std::vector<float> Floats(int accessorIndex, int width)
  {
    if (accessorIndex < 0 || accessorIndex >= int(m_model.accessors.size()))
      throw SceneError(m_path + ": error: accessor " + std::to_string(accessorIndex) + " does not exist");
    const tinygltf::Accessor& a = m_model.accessors[accessorIndex];
    const int comps = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    if (comps != width)
      throw SceneError(m_path + ": error: accessor " + std::to_string(accessorIndex) + " has " + std::to_string(comps) + " components, " +
                       std::to_string(width) + " expected");
    std::vector<float> out(a.count * size_t(width), 0.0f);
    if (a.bufferView < 0)  // all zero (sparse accessors are not read)
      return out;
    const tinygltf::BufferView& view = m_model.bufferViews.at(size_t(a.bufferView));
    const tinygltf::Buffer& buffer = m_model.buffers.at(size_t(view.buffer));
    const int compSize = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
    const size_t stride = view.byteStride ? view.byteStride : size_t(compSize * comps);
    const size_t start = view.byteOffset + a.byteOffset;
    if (a.count > 0 && start + stride * (a.count - 1) + size_t(compSize * comps) > buffer.data.size())
      throw SceneError(m_path + ": error: accessor " + std::to_string(accessorIndex) + " reads past the end of its buffer");
    for (size_t i = 0; i < a.count; ++i)
      for (int c = 0; c < comps; ++c)
      {
        const unsigned char* p = buffer.data.data() + start + i * stride + size_t(c * compSize);
        float v = 0.0f;
        switch (a.componentType)
        {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: std::memcpy(&v, p, 4); break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: v = float(*p) / 255.0f; break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t s; std::memcpy(&s, p, 2); v = float(s) / 65535.0f; break; }
        case TINYGLTF_COMPONENT_TYPE_BYTE: v = std::max(float(*reinterpret_cast<const int8_t*>(p)) / 127.0f, -1.0f); break;
        case TINYGLTF_COMPONENT_TYPE_SHORT: { int16_t s; std::memcpy(&s, p, 2); v = std::max(float(s) / 32767.0f, -1.0f); break; }
        default: throw SceneError(m_path + ": error: accessor " + std::to_string(accessorIndex) + " has an unsupported component type");
        }
        out[i * size_t(width) + size_t(c)] = v;
      }
    return out;
  }

  std::vector<uint32_t> Indices(int accessorIndex)
  {
    if (accessorIndex < 0 || accessorIndex >= int(m_model.accessors.size()))
      throw SceneError(m_path + ": error: index accessor " + std::to_string(accessorIndex) + " does not exist");
    const tinygltf::Accessor& a = m_model.accessors[accessorIndex];
    const tinygltf::BufferView& view = m_model.bufferViews.at(size_t(a.bufferView));
    const tinygltf::Buffer& buffer = m_model.buffers.at(size_t(view.buffer));
    const int size = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
    const size_t stride = view.byteStride ? view.byteStride : size_t(size);
    const size_t start = view.byteOffset + a.byteOffset;
    if (a.count > 0 && start + stride * (a.count - 1) + size_t(size) > buffer.data.size())
      throw SceneError(m_path + ": error: index accessor " + std::to_string(accessorIndex) + " reads past the end of its buffer");
    std::vector<uint32_t> out(a.count);
    for (size_t i = 0; i < a.count; ++i)
    {
      const unsigned char* p = buffer.data.data() + start + i * stride;
      if (size == 1)
        out[i] = *p;
      else if (size == 2)
      {
        uint16_t s;
        std::memcpy(&s, p, 2);
        out[i] = s;
      }
      else
        std::memcpy(&out[i], p, 4);
    }
    return out;
  }

  // All triangle primitives of a mesh as one PathScene mesh, with a material per triangle.
  int ReadMesh(const tinygltf::Mesh& gm)
  {
    PathScene::Mesh mesh;
    mesh.name = gm.name;
    bool allNormals = true, anyUv = false;
    for (const auto& prim : gm.primitives)
      if (prim.mode == TINYGLTF_MODE_TRIANGLES || prim.mode == -1)
      {
        allNormals = allNormals && prim.attributes.count("NORMAL");
        anyUv = anyUv || prim.attributes.count("TEXCOORD_0");
      }
    for (const auto& prim : gm.primitives)
    {
      if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1)
      {
        m_scene.notes.push_back(m_path + ": mesh '" + gm.name + "': a primitive of mode " + std::to_string(prim.mode) + " (not triangles) is skipped");
        continue;
      }
      const auto pos = prim.attributes.find("POSITION");
      if (pos == prim.attributes.end())
        throw SceneError(m_path + ": error: mesh '" + gm.name + "' has a primitive without POSITION");
      const std::vector<float> p = Floats(pos->second, 3);
      const size_t n = p.size() / 3, base = mesh.positions.size();
      std::vector<float> nrm, uv;
      if (allNormals)
        nrm = Floats(prim.attributes.at("NORMAL"), 3);
      if (prim.attributes.count("TEXCOORD_0"))
        uv = Floats(prim.attributes.at("TEXCOORD_0"), 2);
      for (size_t i = 0; i < n; ++i)
      {
        mesh.positions.push_back(float4(p[3 * i], p[3 * i + 1], p[3 * i + 2], 1.0f));
        if (allNormals)
          mesh.normals.push_back(float4(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2], 0.0f));
        if (anyUv)
          mesh.texcoords.push_back(uv.empty() ? float2(0.0f) : float2(uv[2 * i], uv[2 * i + 1]));
      }
      std::vector<uint32_t> idx;
      if (prim.indices >= 0)
        idx = Indices(prim.indices);
      else
        for (size_t i = 0; i < n; ++i)
          idx.push_back(uint32_t(i));
      const uint32_t material = prim.material >= 0 && prim.material < int(m_model.materials.size()) ? uint32_t(prim.material) : m_defaultMaterial;
      for (size_t t = 0; t + 2 < idx.size(); t += 3)
      {
        if (idx[t] >= n || idx[t + 1] >= n || idx[t + 2] >= n)
          throw SceneError(m_path + ": error: mesh '" + gm.name + "' has an index past its " + std::to_string(n) + " vertices");
        for (int k = 0; k < 3; ++k)
          mesh.indices.push_back(uint32_t(base) + idx[t + size_t(k)]);
        mesh.triangleMaterial.push_back(material);
      }
    }
    if (!allNormals)
      MakeFlat(mesh);
    bool normalMap = false;
    for (uint32_t m : mesh.triangleMaterial)
      normalMap = normalMap || m_scene.materials[m]->TextureIds().z >= 0;
    if (normalMap && !mesh.texcoords.empty())
      ComputeTangents(mesh);
    m_scene.meshes.push_back(std::move(mesh));
    return int(m_scene.meshes.size()) - 1;
  }

  std::string m_path;
  PathScene& m_scene;
  tinygltf::Model m_model;
  std::vector<int> m_meshOf;  // glTF mesh -> PathScene mesh
  std::map<std::pair<int, bool>, int> m_textureOf;
  uint32_t m_defaultMaterial = 0;
};

// ---------------------------------------------------------------- OBJ (assimp)

void ReadObj(const std::string& path, PathScene& scene)
{
  Assimp::Importer importer;
  const aiScene* ai = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_GenSmoothNormals | aiProcess_JoinIdenticalVertices);
  if (ai == nullptr || ai->mRootNode == nullptr)
    throw SceneError(path + ": error: not a readable OBJ file: " + importer.GetErrorString());
  const std::string dir = std::filesystem::path(path).parent_path().string();
  std::map<std::string, int> textureOf;
  for (unsigned i = 0; i < ai->mNumMaterials; ++i)
  {
    const aiMaterial* m = ai->mMaterials[i];
    aiColor3D kd(0.8f, 0.8f, 0.8f), ke(0.0f, 0.0f, 0.0f), ks(0.0f, 0.0f, 0.0f);
    float ns = 0.0f, ni = 1.5f, opacity = 1.0f;
    m->Get(AI_MATKEY_COLOR_DIFFUSE, kd);
    m->Get(AI_MATKEY_COLOR_EMISSIVE, ke);
    m->Get(AI_MATKEY_COLOR_SPECULAR, ks);
    m->Get(AI_MATKEY_SHININESS, ns);
    m->Get(AI_MATKEY_REFRACTI, ni);
    m->Get(AI_MATKEY_OPACITY, opacity);
    aiString name;
    m->Get(AI_MATKEY_NAME, name);
    int tex = -1;
    aiString texPath;
    if (m->GetTexture(aiTextureType_DIFFUSE, 0, &texPath) == AI_SUCCESS)
    {
      const std::string file = (std::filesystem::path(dir) / texPath.C_Str()).string();
      if (!textureOf.count(file))
      {
        LiteImage::Image2D<float4> img;
        if (!LiteImage::LoadImage(file.c_str(), img))
          throw SceneError(path + ": error: material '" + name.C_Str() + "': the texture '" + file + "' could not be read");
        for (auto& t : img.vector())
          t = float4(SrgbToLinear(t.x), SrgbToLinear(t.y), SrgbToLinear(t.z), t.w);
        LiteImage::Sampler s;
        s.filter = LiteImage::Sampler::Filter::LINEAR;
        textureOf[file] = int(scene.textures.size());
        scene.textures.emplace_back(std::move(img), s);
      }
      tex = textureOf[file];
    }
    if (opacity < 1.0f)  // MTL's transparency: glass of index Ni
    {
      auto d = std::make_shared<litept::Dielectric>();
      d->ior = ni > 1.0f ? ni : 1.5f;
      scene.materials.push_back(d);
    }
    else if (ks.r + ks.g + ks.b > 0.0f && ns > 0.0f)
    {
      auto p = std::make_shared<litept::Plastic>();
      p->diffuse = float4(kd.r, kd.g, kd.b, 0.0f);
      p->alpha = std::sqrt(2.0f / (ns + 2.0f));  // Phong exponent to Beckmann-like alpha
      const float lum = litept::Luminance(float3(kd.r, kd.g, kd.b));
      p->diffuseChance = LiteMath::clamp(lum / (lum + 0.1f), 0.2f, 0.9f);
      if (tex >= 0)
        scene.notes.push_back(path + ": material '" + std::string(name.C_Str()) + "': the plastic's diffuse texture is ignored");
      scene.materials.push_back(p);
    }
    else
    {
      auto l = std::make_shared<litept::Lambert>();
      l->albedo = float4(kd.r, kd.g, kd.b, 0.0f);
      l->emission = float4(ke.r, ke.g, ke.b, 0.0f);
      l->baseColorTexture = tex;
      scene.materials.push_back(l);
    }
    scene.materialNames.push_back(name.C_Str());
  }
  // Every mesh once, placed by the node hierarchy.
  std::vector<int> meshOf(ai->mNumMeshes, -1);
  std::function<void(const aiNode*, const float4x4&)> visit = [&](const aiNode* node, const float4x4& parent) {
    float4x4 local;
    const aiMatrix4x4& t = node->mTransformation;
    for (int r = 0; r < 4; ++r)
      local.set_row(r, float4(t[r][0], t[r][1], t[r][2], t[r][3]));
    const float4x4 world = parent * local;
    for (unsigned k = 0; k < node->mNumMeshes; ++k)
    {
      const unsigned mi = node->mMeshes[k];
      if (meshOf[mi] < 0)
      {
        const aiMesh* am = ai->mMeshes[mi];
        PathScene::Mesh mesh;
        mesh.name = am->mName.C_Str();
        for (unsigned v = 0; v < am->mNumVertices; ++v)
        {
          mesh.positions.push_back(float4(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z, 1.0f));
          const aiVector3D n = am->mNormals ? am->mNormals[v] : aiVector3D(0.0f, 0.0f, 1.0f);
          mesh.normals.push_back(float4(n.x, n.y, n.z, 0.0f));
          if (am->mTextureCoords[0])
            mesh.texcoords.push_back(float2(am->mTextureCoords[0][v].x, 1.0f - am->mTextureCoords[0][v].y));
        }
        for (unsigned f = 0; f < am->mNumFaces; ++f)
          if (am->mFaces[f].mNumIndices == 3)
          {
            for (int c = 0; c < 3; ++c)
              mesh.indices.push_back(am->mFaces[f].mIndices[c]);
            mesh.triangleMaterial.push_back(am->mMaterialIndex);
          }
        meshOf[mi] = int(scene.meshes.size());
        scene.meshes.push_back(std::move(mesh));
      }
      if (!scene.meshes[meshOf[mi]].indices.empty())
        scene.instances.push_back({uint32_t(meshOf[mi]), world});
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c)
      visit(node->mChildren[c], world);
  };
  visit(ai->mRootNode, float4x4());
}

}  // namespace

PathScene LoadScene(const std::string& path)
{
  if (!std::filesystem::is_regular_file(path))
    throw SceneError(path + ": error: no such file");
  PathScene scene;
  const std::string ext = Lower(std::filesystem::path(path).extension().string());
  if (ext == ".gltf" || ext == ".glb")
  {
    GltfReader reader(path, scene);
    reader.Read();
  }
  else if (ext == ".obj")
    ReadObj(path, scene);
  else
    throw SceneError(path + ": error: unknown scene format '" + ext + "' (expected .gltf, .glb or .obj)");
  if (scene.instances.empty())
    throw SceneError(path + ": error: the scene has no triangles");
  for (const auto& mesh : scene.meshes)
    for (uint32_t m : mesh.triangleMaterial)
      if (m >= scene.materials.size())
        throw SceneError(path + ": error: mesh '" + mesh.name + "' names material " + std::to_string(m) + ", which does not exist");
  return scene;
}

void LoadEnvironment(PathScene& scene, const std::string& path, float strength)
{
  LiteImage::Image2D<float4> env;
  if (!std::filesystem::is_regular_file(path))
    throw SceneError(path + ": error: no such environment map");
  if (!LiteImage::LoadImage(path.c_str(), env) || env.width() == 0 || env.height() == 0)
    throw SceneError(path + ": error: the environment map could not be read (DWAB-compressed EXRs: convert them with "
                            "`oiiotool in.exr --compression zip -o out.exr`)");
  for (auto& t : env.vector())
    t = float4(t.x * strength, t.y * strength, t.z * strength, 1.0f);
  scene.environment = std::move(env);
}

void SceneBounds(const PathScene& scene, float3& boxMin, float3& boxMax)
{
  boxMin = float3(1e30f);
  boxMax = float3(-1e30f);
  for (const auto& inst : scene.instances)
    for (const auto& p : scene.meshes[inst.mesh].positions)
    {
      const float3 w = TransformPoint(inst.toWorld, to_float3(p));
      boxMin = min(boxMin, w);
      boxMax = max(boxMax, w);
    }
}

void ApplySceneDefaults(PathScene& scene)
{
  float3 boxMin, boxMax;
  SceneBounds(scene, boxMin, boxMax);
  if (!scene.hasCamera)
  {
    const float3 centre = (boxMin + boxMax) * 0.5f;
    const float radius = std::max(0.5f * length(boxMax - boxMin), 1e-3f);
    PathScene::Camera& c = scene.camera;
    c.yfov = 0.6911112f;
    c.position = centre + float3(0.0f, 0.0f, radius / std::sin(0.5f * c.yfov));
    c.forward = float3(0.0f, 0.0f, -1.0f);
    c.up = float3(0.0f, 1.0f, 0.0f);
    scene.hasCamera = true;
    scene.notes.push_back("note: the scene has no camera; using the default camera: looking down -z at the bounding sphere's centre (" +
                          std::to_string(centre.x) + ", " + std::to_string(centre.y) + ", " + std::to_string(centre.z) +
                          ") from distance r / sin(yfov / 2), yfov 0.6911 rad");
  }
  bool emits = !scene.lights.empty() || scene.environment.width() > 0;
  for (const auto& m : scene.materials)
  {
    const float3 front = m->Emitted(float3(0.0f, 0.0f, 1.0f), litept::Untextured());
    const float3 back = m->Emitted(float3(0.0f, 0.0f, -1.0f), litept::Untextured());
    emits = emits || front.x + front.y + front.z + back.x + back.y + back.z > 0.0f;
  }
  if (!emits)
  {
    scene.environment = LiteImage::Image2D<float4>(1, 1, float4(1.0f, 1.0f, 1.0f, 1.0f));
    scene.notes.push_back("note: the scene has no light; using the default light: a uniform white environment of radiance 1");
  }
}
