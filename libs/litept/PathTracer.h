// A physically based path tracer written as a plain, single-threaded C++ class in the translator's
// conventions (paper 4.4), translated to PathTracer_CPU (all cores) and PathTracer_Vulkan (compute
// shaders, megakernel or wavefront from the same code) by crossrt_add_class.
//
// RenderPass loops over pixels; per pixel it runs `samples` paths, each a few kernels that pass the
// path's state along in locals: a camera ray (pinhole or thin lens), then per bounce the nearest hit
// through ISceneObject, the shading of the hit (emission weighted by multiple importance sampling,
// one light sample for next-event estimation, one BSDF sample for the next ray, Russian roulette),
// and the light sample's shadow ray. Materials and lights are virtual hierarchies (Materials.h,
// Lights.h); the environment map is importance-sampled through its own 2D distribution.
//
// A pixel's samples depend only on (pixel, sample index, seed), never on threads, passes or the
// backend. The scene comes from PathScene (SceneLoader.h) through SetScene (PathTracerScene.cpp).
#pragma once
#include "CrossRT.h"
#include "Image2D.h"
#include "Lights.h"
#include "LiteMath.h"
#include "Materials.h"

#include <cstdint>
#include <memory>
#include <vector>

struct PathScene;

class PathTracer
{
public:
  PathTracer() = default;
  virtual ~PathTracer() = default;

  // Copies a loaded scene into the tracer's arrays and builds its geometry in `accel`: meshes,
  // instances, materials, textures, lights, the environment and the camera (see PathTracerScene.cpp).
  void SetScene(const PathScene& scene, std::shared_ptr<ISceneObject> accel);
  // Fits the camera's horizontal field of view to an image's width / height: call after SetScene
  // when the image size is known (SetScene uses the scene camera's own aspect, or 1).
  void SetImageAspect(float aspect);
  void SetMaxDepth(int depth) { m_maxDepth = depth; }
  void SetSeed(uint32_t seed) { m_seed = seed; }

  // out_color[y * width + x] = the sum (not the mean) of samples firstSample .. firstSample +
  // samples - 1 of pixel (x, y), row 0 at the top: a pass of a progressive render.
  virtual void RenderPass(uint32_t width, uint32_t height, uint32_t firstSample, int samples,
                          [[crossrt::size("width * height")]] LiteMath::float4* out_color);

  virtual void CommitDeviceData() {}
  virtual void GetExecutionTime(const char* a_funcName, float a_out[4])
  {
    (void)a_funcName;
    for (int i = 0; i < 4; ++i)
      a_out[i] = 0.0f;
  }

  int MaxDepth() const { return m_maxDepth; }
  size_t LightCount() const { return m_lights.size(); }
  bool HasEnvironment() const { return m_envEnabled != 0; }

protected:
  // The path's kernels, in the order RenderPass calls them.
  void kernel_InitEyeRay(uint32_t tidX, uint32_t tidY, uint32_t width, uint32_t height, uint32_t firstSample, int sample,
                         LiteMath::float4* rayPos, LiteMath::float4* rayDir, LiteMath::float4* throughput, LiteMath::float4* pathState);
  void kernel_RayTrace(uint32_t tidX, uint32_t tidY, const LiteMath::float4* rayPos, const LiteMath::float4* rayDir,
                       const LiteMath::float4* throughput, CRT_Hit* hit);
  void kernel_Shade(uint32_t tidX, uint32_t tidY, uint32_t width, uint32_t firstSample, int sample, int bounce, const CRT_Hit* hit,
                    LiteMath::float4* rayPos, LiteMath::float4* rayDir, LiteMath::float4* throughput, LiteMath::float4* pathState,
                    LiteMath::float4* color, LiteMath::float4* shadowPos, LiteMath::float4* shadowDir, LiteMath::float4* shadowColor);
  void kernel_ShadowTrace(uint32_t tidX, uint32_t tidY, const LiteMath::float4* shadowPos, const LiteMath::float4* shadowDir,
                          const LiteMath::float4* shadowColor, LiteMath::float4* color);
  void kernel_Contribute(uint32_t tidX, uint32_t tidY, uint32_t width, const LiteMath::float4* color, LiteMath::float4* out_color);

  // Helpers of kernel_Shade.
  litept::MaterialInputs MaterialInputsAt(LiteMath::int4 textures, LiteMath::float2 uv) const;
  LiteMath::float3 Environment(LiteMath::float3 dir) const;     // radiance from infinity along -dir
  float EnvironmentPdf(LiteMath::float3 dir) const;             // density of SampleEnvironment picking dir
  litept::LightSample SampleEnvironment(LiteMath::float2 u) const;
  uint32_t SampleCdf(uint32_t first, uint32_t count, float u) const;  // i with m_envCdf[first + i] <= u < m_envCdf[first + i + 1]
  float LightChoicePdf(uint32_t light) const;                   // m_lights.size() stands for the environment

  // The scene's geometry: its acceleration structure, and per vertex and triangle what shading needs.
  std::shared_ptr<ISceneObject> m_pAccelStruct;
  std::vector<LiteMath::float4> m_positions;     // object space, per vertex
  std::vector<LiteMath::float4> m_normals;       // object space, per vertex (unit)
  std::vector<LiteMath::float4> m_tangents;      // xyz object space, w the bitangent's sign (glTF)
  std::vector<LiteMath::float2> m_texcoords;     // per vertex
  std::vector<uint32_t> m_indices;               // three per triangle, into the vertex arrays
  std::vector<uint32_t> m_triangleMaterial;      // per triangle
  std::vector<uint32_t> m_geomFirstTriangle;     // per geometry id: its first triangle
  std::vector<LiteMath::float4x4> m_instToWorld;  // per instance id
  std::vector<LiteMath::float4x4> m_instNormalToWorld;  // the inverse transpose
  std::vector<int> m_instFirstLight;             // per instance: its triangle lights' first entry in m_triangleLight, or -1
  std::vector<int> m_triangleLight;              // per triangle of such an instance: its light, or -1

  std::vector<std::shared_ptr<litept::IMaterial>> m_materials;
  std::vector<LiteImage::Texture2D<LiteMath::float4>> m_textures;  // linear rgb(a)

  // Lights: picked for next-event estimation in proportion to m_lightCdf; the environment, if
  // any, is the last choice (index m_lights.size()).
  std::vector<std::shared_ptr<litept::ILight>> m_lights;
  std::vector<float> m_lightCdf;  // m_lights.size() + 2 entries: 0, ..., 1
  // The lights with shapes of their own (spheres, rectangles), which rays meet outside the scene's
  // geometry; never empty on the GPU: m_shapeLightCount says how many there are.
  std::vector<uint32_t> m_shapeLights;
  uint32_t m_shapeLightCount = 0;

  // The environment: an equirectangular map (Blender's orientation, see Environment()), bilinear,
  // and its distribution: rows by m_envCdf[0 .. h], then row r's columns at (h + 1) + r (w + 1).
  LiteImage::Image2D<LiteMath::float4> m_envMap{1, 1, LiteMath::float4(0.0f)};
  LiteImage::Sampler m_envSampler;
  std::vector<float> m_envCdf{0.0f, 1.0f};
  int m_envEnabled = 0;

  // The camera: position, forward (unit), right and up scaled by the tangent of half the field of
  // view (right also by the aspect ratio); a lens of this radius focused at this distance (0: pinhole).
  LiteMath::float4 m_camPos{0.0f, 0.0f, 0.0f, 0.0f};
  LiteMath::float4 m_camForward{0.0f, 0.0f, -1.0f, 0.0f};
  LiteMath::float4 m_camRight{0.4f, 0.0f, 0.0f, 0.0f};
  LiteMath::float4 m_camUp{0.0f, 0.4f, 0.0f, 0.0f};
  LiteMath::float4 m_upHint{0.0f, 1.0f, 0.0f, 0.0f};  // the scene camera's up, for SetImageAspect
  float m_lensRadius = 0.0f;
  float m_focusDistance = 1.0f;
  float m_tanHalfFovY = 0.4f;

  int m_maxDepth = 8;      // bounces, as Cycles counts them (0: direct light only)
  uint32_t m_seed = 0;
  float m_sceneRadius = 1.0f;  // for ray offsets
};
