#include "Constructs.h"

#include <algorithm>
#include <cmath>

Constructs::Constructs(int tableSize)
{
  for (int i = 0; i < tableSize; ++i) m_table.push_back(std::sin(0.1f * float(i)));
}

float Constructs::Shade(float v, int i) const
{
  float acc = v;
  int k = 0;
  while (k < kRounds)  // a while loop
  {
    acc = acc * 0.5f + m_table[(i + k) % int(m_table.size())];
    k++;
  }
  switch (i % 3)
  {
    case 0: acc += 1.0f; break;
    case 1: acc -= 1.0f; break;
    default: break;
  }
  return acc;
}

void Constructs::Saxpy(int n, float a, const float* x, float* y)
{
  kernel1D_Saxpy(n, a, x, y);
}

void Constructs::kernel1D_Saxpy(int n, float a, const float* x, float* y)
{
  const float bias = m_bias * kScale;  // declaration before the loop
  for (int i = 0; i < n; i++)
  {
    if (i % 7 == 3)
      continue;  // this element stays as it was
    const unsigned int bits = unsigned(i) * 2654435761u;
    const float jitter = float(bits >> 24) / 255.0f;
    float v = a * x[i] + y[i] + bias + SmoothPulse(jitter);
    v = i % 2 == 0 ? Shade(v, i) : std::abs(v);
    y[i] = v + float(int(v * 4.0f)) * 0.125f;
  }
}

void Constructs::Stats(int n, const float* values, const float3* points)
{
  m_sum = 0.0f;
  m_negSum = 0.0f;
  m_min = INF_POSITIVE;
  m_positives = 0;
  m_maxBits = 0;
  m_boxMin = float3(INF_POSITIVE);
  m_boxMax = float3(INF_NEGATIVE);
  kernel1D_Stats(n, values, points);
}

void Constructs::kernel1D_Stats(int n, const float* values, const float3* points)
{
  for (int i = 0; i < n; i++)
  {
    const float v = values[i];
    m_sum += v;
    m_negSum -= 0.5f * v;
    m_min = std::min(m_min, v);
    if (v > 0.0f)
      m_positives += 1;
    m_maxBits = std::max(m_maxBits, as_uint(std::abs(v)) >> 8);
    m_boxMin = min(m_boxMin, points[i]);
    m_boxMax = max(m_boxMax, points[i]);
  }
}

void Constructs::Structs(int n, const Particle* in, Particle* out)
{
  kernel1D_Structs(n, in, out);
}

void Constructs::kernel1D_Structs(int n, const Particle* in, Particle* out)
{
  for (int i = 0; i < n; i++)
  {
    Particle p = in[i];
    p.position = p.position + float4(p.color, 0.0f) * p.mass;
    p.color = normalize(p.color + float3(1.0f, 2.0f, 3.0f));
    p.mass = length(p.position) + dot(p.color, float3(0.5f));
    out[i] = p;
  }
}

void Constructs::Grid(int w, int h, uint32_t* out, float* row)
{
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      kernel_GridCell(x, y, w, out);
  for (int i = 0; i < w; i++)
    kernel_Row(uint32_t(i), row);
}

void Constructs::kernel_GridCell(int tidX, int tidY, int w, uint32_t* out)
{
  const uint32_t hash = uint32_t(tidX) * 73856093u ^ uint32_t(tidY) * 19349663u;
  out[tidY * w + tidX] = hash % 1000u;
}

void Constructs::kernel_Row(uint32_t tid, float* row)
{
  row[tid] = SmoothPulse(float(tid) * 0.01f) + m_table[tid % m_table.size()];
}

void Constructs::Volume(int nx, int ny, int nz, float* out)
{
  kernel3D_Volume(nx, ny, nz, out);
}

void Constructs::kernel3D_Volume(int nx, int ny, int nz, float* out)
{
  for (int z = 0; z < nz; z++)
    for (int y = 1; y < ny; y++)       // starts at 1: row 0 stays untouched
      for (int x = 0; x <= nx - 1; x++)  // inclusive bound
      {
        const float3 p = float3(float(x), float(y), float(z)) * kScale;
        out[(z * ny + y) * nx + x] = length(p - float3(2.0f)) - 1.5f;
      }
}

void Constructs::FillSquares(int n)
{
  kernel1D_Squares(n);
}

void Constructs::RoundTripHalves(int n, float scale, const float4* in, float4* out)
{
  kernel1D_ToHalves(n, scale, in);
  kernel1D_FromHalves(n, scale, out);
}

void Constructs::kernel1D_ToHalves(int n, float scale, const float4* in)
{
  for (int i = 0; i < n; i++)
    m_halves[i] = i % 2 == 0 ? half4(in[i] * scale) : half4(in[i].x * scale, in[i].y * scale, in[i].z * scale, in[i].w * scale);
}

void Constructs::kernel1D_FromHalves(int n, float scale, float4* out)
{
  for (int i = 0; i < n; i++)
    out[i] = to_float4(m_halves[i]) / scale;
}

void Constructs::kernel1D_Squares(int n)
{
  for (int i = 0; i < n; i++)
    m_squares[i] = i * i - int(m_squares.size());
}
