// Rendering and training a ReLU field (paper 4.3), in plain C++ that CrossRT translates to
// ReluField_CPU (all cores) and ReluField_Vulkan. Rays follow the NeRF synthetic dataset's pinhole
// camera; colour is composited front to back over a white background.
//  - Render marches each pixel's ray with a constant step (the original method), or visits only the
//    occupied cells through RFCellTree, front to back, with one sample per cell at the middle of the
//    ray's chord through it and the chord's real length as the step (the paper's method). Both stop
//    once the transmittance falls below a threshold.
//  - TrainStep runs a batch of rays forward and backward (analytic gradients of the mean squared
//    error, scattered to the grid's vertices) and takes one Adam step on every value.
#pragma once
#include "LiteMath.h"
#include "RFCellTree.h"
#include "RFGrid.h"

#include <cstdint>
#include <vector>

using LiteMath::float3;
using LiteMath::float4;

class ReluField
{
public:
  static constexpr int kMarch = 0;  // constant steps of m_stepCells cells
  static constexpr int kCells = 1;  // one sample per occupied cell, front to back

  ReluField(int width, int height) : m_width(width), m_height(height) {}
  virtual ~ReluField() = default;

  // The field to render or train (its values, its occupied cells' tree). Resets the optimiser.
  // Translated classes need CommitDeviceData() after it.
  void SetGrid(const literf::RFGrid& grid);
  // The camera of a NeRF frame: its camera-to-world matrix (rows as in transforms.json) and the focal
  // length in pixels, 0.5 * width / tan(0.5 * camera_angle_x).
  void SetCamera(const LiteMath::float4x4& cameraToWorld, float focal);
  void SetMethod(int method) { m_method = method; }
  void SetStopTransmittance(float t) { m_stopTransmittance = t; }
  void SetMarchStep(float cells) { m_stepCells = cells; }
  void SetLearningRate(float rate) { m_learningRate = rate; }

  // Linear RGB of every pixel (alpha 1), row 0 at the top.
  virtual void Render([[crossrt::size("m_width * m_height")]] float4* colours);
  // One optimisation step on `rays` rays (origin, unit direction, target RGB); losses[i] is ray i's
  // squared error (mean over RGB) before the step.
  virtual void TrainStep(int rays, [[crossrt::size("rays")]] const float4* origins, [[crossrt::size("rays")]] const float4* dirs,
                         [[crossrt::size("rays")]] const float4* targets, [[crossrt::size("rays")]] float* losses);
  // The field's values as they are now (after training on a device, they are there).
  virtual void ReadValues(int count, [[crossrt::size("count")]] float* out);

  virtual void CommitDeviceData() {}
  virtual void GetExecutionTime(const char* a_funcName, float a_out[4])
  {
    (void)a_funcName;
    for (int i = 0; i < 4; ++i)
      a_out[i] = 0.0f;
  }

  int ValueCount() const { return int(m_values.size()); }

protected:
  void kernel2D_Render(float4* colours, int width, int height);
  void kernel1D_ZeroGradients(int count);
  void kernel1D_Backward(int rays, const float4* origins, const float4* dirs, const float4* targets, float* losses);
  void kernel1D_Adam(int count);
  void kernel1D_ReadValues(int count, float* out);

  // The ray's span inside the grid's box, [tNear, tFar]; false when it misses.
  bool BoxSpan(float3 org, float3 dir, float& tNear, float& tFar) const;
  // The cell holding p: the index of its lowest vertex, and p's place inside it ([0, 1]³).
  void Locate(float3 p, int& firstVertex, float3& place) const;
  // From a cell's lowest vertex to its corner (bit 0: +x, 1: +y, 2: +z), in vertices.
  int CornerOffset(int corner) const;
  // Density and colour at p seen along dir (raw: the trilinear raw density, before ReLU).
  void Sample(float3 p, float3 dir, float& density, float& raw, float3& colour) const;
  // Adds the gradients of one sample (of its density and colour) to its 8 vertices.
  void ScatterGradient(float3 p, float3 dir, float raw, float3 colour, float dDensity, float3 dColour);
  // Adds a segment of length delta sampled at p to the colour, behind the transmittance so far.
  void Composite(float3 p, float3 dir, float delta, float3& colour, float& transmittance) const;
  // The colour of a ray and the transmittance left: constant steps, or the occupied cells.
  float3 March(float3 org, float3 dir, float& transmittance) const;
  float3 TraverseCells(float3 org, float3 dir, float& transmittance) const;

  int m_width, m_height;
  int m_method = kCells;
  // The grid (RFGrid): cells per axis, values per vertex, SH coefficients per channel.
  int m_cells = 0, m_channels = 1, m_shCoefficients = 1;
  float4 m_boxMin = float4(-1.5f, -1.5f, -1.5f, 0.0f), m_boxMax = float4(1.5f, 1.5f, 1.5f, 0.0f);
  float m_densityScale = 100.0f;
  float m_stopTransmittance = 0.01f;
  float m_stepCells = 0.5f;
  // The camera: position, and the directions of a pixel step right and down and of the image centre.
  float4 m_camPos, m_camRight, m_camDown, m_camCentre;
  // Adam (Kingma and Ba 2015): the rate and its bias-corrected form for the next step.
  float m_learningRate = 0.01f, m_beta1 = 0.9f, m_beta2 = 0.999f, m_epsilon = 1e-8f;
  float m_stepRate = 0.0f;
  int m_steps = 0;
  float m_gradientScale = 1.0f;  // 1 / rays of the batch: the loss is their mean

  std::vector<float> m_values, m_gradients, m_moment1, m_moment2;
  std::vector<literf::RFNode> m_nodes;
};
