// A test class that uses every construct the first translator slice supports. Its original,
// _CPU and _Vulkan versions must agree (test/equivalence/test_constructs.cpp).
#pragma once
#include "LiteMath.h"

#include <cstdint>
#include <vector>

using namespace LiteMath;

// std430 matches C++ here: float4 at 0, float3 at 16 (12 bytes), float at 28.
struct Particle
{
  float4 position;
  float3 color;
  float mass;
};

constexpr float kScale = 0.5f;
constexpr int kRounds = 3;

// A free function kernels call (becomes a GLSL function).
inline float SmoothPulse(float x) { return x <= 0.0f ? 0.0f : x >= 1.0f ? 1.0f : x * x * (3.0f - 2.0f * x); }

class Constructs
{
public:
  explicit Constructs(int tableSize);
  virtual ~Constructs() = default;

  // IPV 1D with a helper member function, loops, switch, casts, continue.
  virtual void Saxpy(int n, float a, [[crossrt::size("n")]] const float* x, [[crossrt::size("n")]] float* y);
  // Reductions (+=, -=, min, max) on float, int, uint and float3 members.
  virtual void Stats(int n, [[crossrt::size("n")]] const float* values, [[crossrt::size("n")]] const float3* points);
  // Arrays of a user struct; the paper's GNU size attribute.
  virtual void Structs(int n, const Particle* in __attribute__((size("n"))), Particle* out __attribute__((size("n"))));
  // RTV kernels: kernel_* called from loops, 1D and 2D.
  virtual void Grid(int w, int h, [[crossrt::size("w*h")]] uint32_t* out, [[crossrt::size("w")]] float* row);
  // IPV 3D, a loop that starts at 1, an inclusive bound.
  virtual void Volume(int nx, int ny, int nz, [[crossrt::size("nx*ny*nz")]] float* out);
  // A kernel that writes a std::vector member, which the generated class reads back.
  virtual void FillSquares(int n);
  // 16-bit floats: m_halves[i] = half4(in[i] * scale), then out[i] = to_float4(m_halves[i]) / scale,
  // through a member vector of half4 between two kernels (the caller sizes m_halves).
  virtual void RoundTripHalves(int n, float scale, [[crossrt::size("n")]] const float4* in, [[crossrt::size("n")]] float4* out);

  virtual void CommitDeviceData() {}
  virtual void GetExecutionTime(const char* a_funcName, float a_out[4]) { (void)a_funcName; for (int i = 0; i < 4; ++i) a_out[i] = 0.0f; }

  float m_sum = 0.0f, m_negSum = 0.0f, m_min = 0.0f;
  int m_positives = 0;
  uint32_t m_maxBits = 0;
  float3 m_boxMin, m_boxMax;
  std::vector<int> m_squares;
  std::vector<half4> m_halves;

protected:
  void kernel1D_Saxpy(int n, float a, const float* x, float* y);
  void kernel1D_Stats(int n, const float* values, const float3* points);
  void kernel1D_Structs(int n, const Particle* in, Particle* out);
  void kernel_GridCell(int tidX, int tidY, int w, uint32_t* out);
  void kernel_Row(uint32_t tid, float* row);
  void kernel3D_Volume(int nx, int ny, int nz, float* out);
  void kernel1D_Squares(int n);
  void kernel1D_ToHalves(int n, float scale, const float4* in);
  void kernel1D_FromHalves(int n, float scale, float4* out);

  float Shade(float v, int i) const;  // helper member function

  std::vector<float> m_table;  // read by kernels
  float m_bias = 0.25f;
};
