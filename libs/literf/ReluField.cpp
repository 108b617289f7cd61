#include "ReluField.h"

#include <algorithm>
#include <cmath>

namespace {

// The real spherical harmonics of degree 0 to 2 in direction d (unit), in the order of the grid's
// coefficients (the constants of Sloan's "Stupid Spherical Harmonics Tricks").
struct ShBasis
{
  float value[9];
};

ShBasis EvaluateSh(float3 d)
{
  ShBasis sh;
  sh.value[0] = 0.28209479f;
  sh.value[1] = -0.48860251f * d.y;
  sh.value[2] = 0.48860251f * d.z;
  sh.value[3] = -0.48860251f * d.x;
  sh.value[4] = 1.09254843f * d.x * d.y;
  sh.value[5] = -1.09254843f * d.y * d.z;
  sh.value[6] = 0.31539157f * (2.0f * d.z * d.z - d.x * d.x - d.y * d.y);
  sh.value[7] = -1.09254843f * d.x * d.z;
  sh.value[8] = 0.54627422f * (d.x * d.x - d.y * d.y);
  return sh;
}

float Sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }

float3 Xyz(float4 v) { return float3(v.x, v.y, v.z); }

// The trilinear weight of a cell's corner (bit 0: x, 1: y, 2: z) at place f inside the cell.
float CornerWeight(int corner, float3 f)
{
  return ((corner & 1) != 0 ? f.x : 1.0f - f.x) * ((corner & 2) != 0 ? f.y : 1.0f - f.y) * ((corner & 4) != 0 ? f.z : 1.0f - f.z);
}

}  // namespace

void ReluField::SetGrid(const literf::RFGrid& grid)
{
  m_cells = grid.cells;
  m_channels = grid.Channels();
  m_shCoefficients = literf::ShCoefficients(grid.shDegree);
  m_boxMin = float4(grid.boxMin.x, grid.boxMin.y, grid.boxMin.z, 0.0f);
  m_boxMax = float4(grid.boxMax.x, grid.boxMax.y, grid.boxMax.z, 0.0f);
  m_densityScale = grid.densityScale;
  m_values = grid.values;
  m_gradients.assign(m_values.size(), 0.0f);
  m_moment1.assign(m_values.size(), 0.0f);
  m_moment2.assign(m_values.size(), 0.0f);
  m_steps = 0;
  m_nodes = literf::BuildCellTree(grid);
  if (m_nodes.empty())  // nothing occupied: a root that no ray meets (its box is inverted)
  {
    literf::RFNode none;
    none.boxMin = float3(1.0f, 1.0f, 1.0f);
    none.boxMax = float3(-1.0f, -1.0f, -1.0f);
    none.left = literf::kCellLeaf;
    none.axis = 0;
    m_nodes.push_back(none);
  }
}

void ReluField::SetCamera(const LiteMath::float4x4& cameraToWorld, float focal)
{
  // NeRF's camera looks down its -z axis with y up; pixel (x, y) is at ((x + 0.5 - w/2) / f,
  // -(y + 0.5 - h/2) / f, -1) in camera space.
  const float4 right = cameraToWorld.get_col(0), up = cameraToWorld.get_col(1), back = cameraToWorld.get_col(2);
  m_camPos = cameraToWorld.get_col(3);
  m_camRight = right / focal;
  m_camDown = up * (-1.0f / focal);
  m_camCentre = back * -1.0f - m_camRight * (0.5f * float(m_width)) - m_camDown * (0.5f * float(m_height));
}

bool ReluField::BoxSpan(float3 org, float3 dir, float& tNear, float& tFar) const
{
  const float3 inv = float3(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z);
  const float3 t0 = (Xyz(m_boxMin) - org) * inv, t1 = (Xyz(m_boxMax) - org) * inv;
  const float3 lo = LiteMath::min(t0, t1), hi = LiteMath::max(t0, t1);
  tNear = std::max(std::max(lo.x, lo.y), std::max(lo.z, 0.0f));
  tFar = std::min(std::min(hi.x, hi.y), hi.z);
  return tNear < tFar;
}

void ReluField::Locate(float3 p, int& firstVertex, float3& place) const
{
  const float3 u = (p - Xyz(m_boxMin)) / (Xyz(m_boxMax) - Xyz(m_boxMin)) * float(m_cells);
  const int x = std::min(std::max(int(std::floor(u.x)), 0), m_cells - 1);
  const int y = std::min(std::max(int(std::floor(u.y)), 0), m_cells - 1);
  const int z = std::min(std::max(int(std::floor(u.z)), 0), m_cells - 1);
  place = LiteMath::clamp(u - float3(float(x), float(y), float(z)), 0.0f, 1.0f);
  firstVertex = x + (m_cells + 1) * (y + (m_cells + 1) * z);
}

int ReluField::CornerOffset(int corner) const
{
  const int vertices = m_cells + 1;
  return (corner & 1) + vertices * (((corner >> 1) & 1) + vertices * (corner >> 2));
}

void ReluField::Sample(float3 p, float3 dir, float& density, float& raw, float3& colour) const
{
  int first;
  float3 f;
  Locate(p, first, f);
  const ShBasis sh = EvaluateSh(dir);
  raw = 0.0f;
  float3 z3 = float3(0.0f, 0.0f, 0.0f);  // the colour before the sigmoid
  for (int corner = 0; corner < 8; ++corner)
  {
    const float w = CornerWeight(corner, f);
    const int base = (first + CornerOffset(corner)) * m_channels;
    raw += w * m_values[base];
    for (int k = 0; k < m_shCoefficients; ++k)
    {
      z3.x += w * sh.value[k] * m_values[base + 1 + k];
      z3.y += w * sh.value[k] * m_values[base + 1 + m_shCoefficients + k];
      z3.z += w * sh.value[k] * m_values[base + 1 + 2 * m_shCoefficients + k];
    }
  }
  density = std::max(raw, 0.0f) * m_densityScale;
  colour = float3(Sigmoid(z3.x), Sigmoid(z3.y), Sigmoid(z3.z));
}

void ReluField::ScatterGradient(float3 p, float3 dir, float raw, float3 colour, float dDensity, float3 dColour)
{
  int first;
  float3 f;
  Locate(p, first, f);
  const ShBasis sh = EvaluateSh(dir);
  // Through the ReLU and the sigmoids to the interpolated values.
  const float dRaw = raw > 0.0f ? dDensity * m_densityScale : 0.0f;
  const float3 dZ = dColour * colour * (float3(1.0f, 1.0f, 1.0f) - colour);
  for (int corner = 0; corner < 8; ++corner)
  {
    const float w = CornerWeight(corner, f);
    const int base = (first + CornerOffset(corner)) * m_channels;
    if (dRaw != 0.0f)
      LiteMath::InterlockedAdd(m_gradients[base], w * dRaw);
    for (int k = 0; k < m_shCoefficients; ++k)
    {
      LiteMath::InterlockedAdd(m_gradients[base + 1 + k], w * sh.value[k] * dZ.x);
      LiteMath::InterlockedAdd(m_gradients[base + 1 + m_shCoefficients + k], w * sh.value[k] * dZ.y);
      LiteMath::InterlockedAdd(m_gradients[base + 1 + 2 * m_shCoefficients + k], w * sh.value[k] * dZ.z);
    }
  }
}

void ReluField::Composite(float3 p, float3 dir, float delta, float3& colour, float& transmittance) const
{
  float density, raw;
  float3 c;
  Sample(p, dir, density, raw, c);
  const float alpha = 1.0f - std::exp(-density * delta);
  colour += c * (transmittance * alpha);
  transmittance *= 1.0f - alpha;
}

float3 ReluField::March(float3 org, float3 dir, float& transmittance) const
{
  float3 colour = float3(0.0f, 0.0f, 0.0f);
  transmittance = 1.0f;
  float tNear, tFar;
  if (!BoxSpan(org, dir, tNear, tFar))
    return colour;
  const float step = m_stepCells * (m_boxMax.x - m_boxMin.x) / float(m_cells);
  for (float t = tNear; t < tFar && transmittance >= m_stopTransmittance; t += step)
  {
    const float delta = std::min(step, tFar - t);
    Composite(org + dir * (t + 0.5f * delta), dir, delta, colour, transmittance);
  }
  return colour;
}

float3 ReluField::TraverseCells(float3 org, float3 dir, float& transmittance) const
{
  float3 colour = float3(0.0f, 0.0f, 0.0f);
  transmittance = 1.0f;
  const float3 inv = float3(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z);
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0 && transmittance >= m_stopTransmittance)
  {
    const literf::RFNode node = m_nodes[stack[--top]];
    const float3 t0 = (node.boxMin - org) * inv, t1 = (node.boxMax - org) * inv;
    const float3 lo = LiteMath::min(t0, t1), hi = LiteMath::max(t0, t1);
    const float enter = std::max(std::max(lo.x, lo.y), std::max(lo.z, 0.0f));
    const float leave = std::min(std::min(hi.x, hi.y), hi.z);
    if (!(enter < leave))
      continue;
    if ((node.left & literf::kCellLeaf) != 0u)
    {
      // One sample in the middle of the chord; the chord's length is the step.
      const float delta = leave - enter;
      Composite(org + dir * (enter + 0.5f * delta), dir, delta, colour, transmittance);
      continue;
    }
    // The child below the plane comes first when the ray runs up the axis.
    const float along = node.axis == 0u ? dir.x : (node.axis == 1u ? dir.y : dir.z);
    const uint32_t nearChild = along >= 0.0f ? node.left : node.left + 1u;
    const uint32_t farChild = along >= 0.0f ? node.left + 1u : node.left;
    stack[top++] = farChild;
    stack[top++] = nearChild;
  }
  return colour;
}

void ReluField::Render(float4* colours) { kernel2D_Render(colours, m_width, m_height); }

void ReluField::kernel2D_Render(float4* colours, int width, int height)
{
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
    {
      const float4 d4 = m_camCentre + m_camRight * (float(x) + 0.5f) + m_camDown * (float(y) + 0.5f);
      const float3 dir = LiteMath::normalize(Xyz(d4));
      float transmittance = 1.0f;
      float3 c = m_method == kMarch ? March(Xyz(m_camPos), dir, transmittance) : TraverseCells(Xyz(m_camPos), dir, transmittance);
      c += float3(transmittance, transmittance, transmittance);  // the white background
      colours[y * width + x] = float4(c.x, c.y, c.z, 1.0f);
    }
}

void ReluField::TrainStep(int rays, const float4* origins, const float4* dirs, const float4* targets, float* losses)
{
  m_steps += 1;
  m_gradientScale = 1.0f / float(rays);
  m_stepRate = m_learningRate * std::sqrt(1.0f - std::pow(m_beta2, float(m_steps))) / (1.0f - std::pow(m_beta1, float(m_steps)));
  const int count = int(m_values.size());
  kernel1D_ZeroGradients(count);
  kernel1D_Backward(rays, origins, dirs, targets, losses);
  kernel1D_Adam(count);
}

void ReluField::kernel1D_ZeroGradients(int count)
{
  for (int i = 0; i < count; ++i)
    m_gradients[i] = 0.0f;
}

void ReluField::kernel1D_Backward(int rays, const float4* origins, const float4* dirs, const float4* targets, float* losses)
{
  for (int r = 0; r < rays; ++r)
  {
    const float3 org = Xyz(origins[r]), dir = Xyz(dirs[r]);
    float transmittance = 1.0f;
    float3 colour = March(org, dir, transmittance);
    colour += float3(transmittance, transmittance, transmittance);  // the white background
    const float3 error = colour - Xyz(targets[r]);
    losses[r] = LiteMath::dot(error, error) / 3.0f;
    // d(mean squared error)/d(colour of the ray), for the batch's mean.
    const float3 dC = error * (2.0f / 3.0f * m_gradientScale);
    float tNear, tFar;
    if (!BoxSpan(org, dir, tNear, tFar))
      continue;
    // Again along the ray: with C the ray's colour, C_i what the samples up to i gave and T_{i+1}
    // the transmittance after sample i, dC/dc_i = T_i alpha_i and
    // dC/dsigma_i = delta_i (T_{i+1} c_i - (C - C_i)) (the background is part of C).
    const float step = m_stepCells * (m_boxMax.x - m_boxMin.x) / float(m_cells);
    float before = 1.0f;
    float3 upTo = float3(0.0f, 0.0f, 0.0f);
    for (float t = tNear; t < tFar && before >= m_stopTransmittance; t += step)
    {
      const float delta = std::min(step, tFar - t);
      const float3 p = org + dir * (t + 0.5f * delta);
      float density, raw;
      float3 c;
      Sample(p, dir, density, raw, c);
      const float alpha = 1.0f - std::exp(-density * delta);
      const float weight = before * alpha, after = before * (1.0f - alpha);
      upTo += c * weight;
      const float dDensity = delta * LiteMath::dot(dC, c * after - (colour - upTo));
      if (weight > 0.0f || dDensity != 0.0f)
        ScatterGradient(p, dir, raw, c, dDensity, dC * weight);
      before = after;
    }
  }
}

void ReluField::kernel1D_Adam(int count)
{
  for (int i = 0; i < count; ++i)
  {
    const float g = m_gradients[i];
    const float m = m_beta1 * m_moment1[i] + (1.0f - m_beta1) * g;
    const float v = m_beta2 * m_moment2[i] + (1.0f - m_beta2) * g * g;
    m_moment1[i] = m;
    m_moment2[i] = v;
    m_values[i] -= m_stepRate * m / (std::sqrt(v) + m_epsilon);
  }
}

void ReluField::ReadValues(int count, float* out) { kernel1D_ReadValues(count, out); }

void ReluField::kernel1D_ReadValues(int count, float* out)
{
  for (int i = 0; i < count; ++i)
    out[i] = m_values[i];
}
