// LiteMath: small GLSL-like vector/matrix library used by CrossRT kernels.
//
// The translator maps these names one-to-one onto GLSL, so the names and semantics
// deliberately follow GLSL (float3 <-> vec3, mix, fract, inversesqrt, ...).
// Matrices are stored column-major (m_col[i] is column i), like GLSL and Vulkan.
//
// It has the public API of the paper's LiteMath (msu-graphics-group/LiteMath) that kernels use:
// its constants (M_PI as a float, M_TWOPI, INV_PI), converting constructors (int2(float2)),
// mul4x4x4, make_float4x4_from_rows/cols, rotate3x3X/Y/Z, mod, cross3, half4, complex,
// InterlockedAdd and the ReduceAdd family. One difference remains: m[i] of a matrix is column i
// here (as in GLSL), row i there.
#pragma once

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <vector>

// float4 arithmetic and min/max on SSE in compiled C++ (compilers do not vectorize the
// four-field struct themselves). Results are bit-identical to the scalar definitions. The
// translator (__CROSSRT__) maps these functions to GLSL by name and never reads their bodies.
#if defined(__SSE2__) && !defined(__CROSSRT__) && !defined(LITEMATH_NO_SIMD)
#define LITEMATH_FLOAT4_SSE 1
#include <xmmintrin.h>
#endif

namespace LiteMath
{
typedef uint32_t uint;

struct float2;
struct float3;
struct float4;
struct int2;
struct int3;
struct int4;
struct uint2;
struct uint3;
struct uint4;
struct half2;
struct half4;

// Bring std scalar functions into this namespace so that LiteMath::min(1.0f, 2.0f) works and
// unqualified calls with `using namespace LiteMath;` see both scalar and vector overloads.
using std::abs;
using std::ceil;
using std::cos;
using std::exp;
using std::floor;
using std::log;
using std::max;
using std::min;
using std::pow;
using std::sin;
using std::sqrt;

// ---------------------------------------------------------------- constants
constexpr float INF_POSITIVE = std::numeric_limits<float>::infinity();
constexpr float INF_NEGATIVE = -std::numeric_limits<float>::infinity();
constexpr float EPSILON      = 1e-6f;
#ifndef M_PI_F // some platforms (OpenCL headers) define it as a macro
constexpr float M_PI_F = 3.14159265358979323846f;
#endif
constexpr float DEG_TO_RAD = 3.14159265358979323846f / 180.0f;
// As in the paper's LiteMath, M_PI is a float in the namespace (it replaces <cmath>'s macro).
#ifdef M_PI
#undef M_PI
#endif
constexpr float M_PI      = 3.14159265358979323846f;
constexpr float M_TWOPI   = 2.0f * M_PI;
constexpr float INV_PI    = 1.0f / M_PI;
constexpr float INV_TWOPI = 1.0f / (2.0f * M_PI);
// OpenCL's address space qualifier, which kernel_slicer's older samples write on pointers.
#ifndef __global
#define __global
#endif
#ifndef MAXFLOAT
#define MAXFLOAT FLT_MAX
#endif

// ---------------------------------------------------------------- scalar helpers std lacks
inline float fract(float x) { return x - std::floor(x); }
inline float sign(float x) { return float((x > 0.0f) - (x < 0.0f)); }
inline int   sign(int x) { return (x > 0) - (x < 0); }
// Non-template clamp: preferred over std::clamp when both are visible.
inline float clamp(float x, float lo, float hi) { return std::min(std::max(x, lo), hi); }
inline int   clamp(int x, int lo, int hi) { return std::min(std::max(x, lo), hi); }
inline uint  clamp(uint x, uint lo, uint hi) { return std::min(std::max(x, lo), hi); }
inline float lerp(float a, float b, float t) { return a + t * (b - a); }
inline float mix(float a, float b, float t) { return a + t * (b - a); }
inline float step(float edge, float x) { return x < edge ? 0.0f : 1.0f; }
inline float smoothstep(float e0, float e1, float x)
{
  const float t = clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}
inline float inversesqrt(float x) { return 1.0f / std::sqrt(x); }

// ---------------------------------------------------------------- vector types
// operator[] indexes the consecutive fields x,y,z,w (standard layout, no padding between them).

struct alignas(8) float2
{
  float x, y;
  float2() : x(0), y(0) {}
  explicit float2(float a) : x(a), y(a) {}
  explicit float2(const float (&a)[2]) : x(a[0]), y(a[1]) {}  // from an array, as LiteMath's
  explicit float2(const int2& v);  // componentwise conversion
  explicit float2(const uint2& v);  // componentwise conversion
  float2(float a_x, float a_y) : x(a_x), y(a_y) {}
  float&       operator[](int i) { return (&x)[i]; }
  const float& operator[](int i) const { return (&x)[i]; }
};

struct float3
{
  float x, y, z;
  float3() : x(0), y(0), z(0) {}
  explicit float3(float a) : x(a), y(a), z(a) {}
  explicit float3(const float (&a)[3]) : x(a[0]), y(a[1]), z(a[2]) {}  // from an array, as LiteMath's
  explicit float3(const int3& v);  // componentwise conversion
  explicit float3(const uint3& v);  // componentwise conversion
  float3(float a_x, float a_y, float a_z) : x(a_x), y(a_y), z(a_z) {}
  float3(float2 v, float a_z) : x(v.x), y(v.y), z(a_z) {}
  float&       operator[](int i) { return (&x)[i]; }
  const float& operator[](int i) const { return (&x)[i]; }
};

struct alignas(16) float4
{
  float x, y, z, w;
  float4() : x(0), y(0), z(0), w(0) {}
  explicit float4(float a) : x(a), y(a), z(a), w(a) {}
  explicit float4(const float (&a)[4]) : x(a[0]), y(a[1]), z(a[2]), w(a[3]) {}  // from an array, as LiteMath's
  explicit float4(const int4& v);  // componentwise conversion
  explicit float4(const uint4& v);  // componentwise conversion
  explicit float4(const half4& v);  // componentwise conversion
  float4(float a_x, float a_y, float a_z, float a_w) : x(a_x), y(a_y), z(a_z), w(a_w) {}
  float4(float3 v, float a_w) : x(v.x), y(v.y), z(v.z), w(a_w) {}
  float&       operator[](int i) { return (&x)[i]; }
  const float& operator[](int i) const { return (&x)[i]; }
};

struct alignas(8) int2
{
  int x, y;
  int2() : x(0), y(0) {}
  explicit int2(int a) : x(a), y(a) {}
  explicit int2(const int (&a)[2]) : x(a[0]), y(a[1]) {}  // from an array, as LiteMath's
  explicit int2(const float2& v);  // componentwise conversion
  explicit int2(const uint2& v);  // componentwise conversion
  int2(int a_x, int a_y) : x(a_x), y(a_y) {}
  int&       operator[](int i) { return (&x)[i]; }
  const int& operator[](int i) const { return (&x)[i]; }
};

struct int3
{
  int x, y, z;
  int3() : x(0), y(0), z(0) {}
  explicit int3(int a) : x(a), y(a), z(a) {}
  explicit int3(const int (&a)[3]) : x(a[0]), y(a[1]), z(a[2]) {}  // from an array, as LiteMath's
  explicit int3(const float3& v);  // componentwise conversion
  explicit int3(const uint3& v);  // componentwise conversion
  int3(int a_x, int a_y, int a_z) : x(a_x), y(a_y), z(a_z) {}
  int3(int2 v, int a_z) : x(v.x), y(v.y), z(a_z) {}
  int&       operator[](int i) { return (&x)[i]; }
  const int& operator[](int i) const { return (&x)[i]; }
};

struct alignas(16) int4
{
  int x, y, z, w;
  int4() : x(0), y(0), z(0), w(0) {}
  explicit int4(int a) : x(a), y(a), z(a), w(a) {}
  explicit int4(const int (&a)[4]) : x(a[0]), y(a[1]), z(a[2]), w(a[3]) {}  // from an array, as LiteMath's
  explicit int4(const float4& v);  // componentwise conversion
  explicit int4(const uint4& v);  // componentwise conversion
  int4(int a_x, int a_y, int a_z, int a_w) : x(a_x), y(a_y), z(a_z), w(a_w) {}
  int4(int3 v, int a_w) : x(v.x), y(v.y), z(v.z), w(a_w) {}
  int&       operator[](int i) { return (&x)[i]; }
  const int& operator[](int i) const { return (&x)[i]; }
};

struct alignas(8) uint2
{
  uint x, y;
  uint2() : x(0), y(0) {}
  explicit uint2(uint a) : x(a), y(a) {}
  explicit uint2(const uint (&a)[2]) : x(a[0]), y(a[1]) {}  // from an array, as LiteMath's
  explicit uint2(const float2& v);  // componentwise conversion
  explicit uint2(const int2& v);  // componentwise conversion
  uint2(uint a_x, uint a_y) : x(a_x), y(a_y) {}
  uint&       operator[](int i) { return (&x)[i]; }
  const uint& operator[](int i) const { return (&x)[i]; }
};

struct uint3
{
  uint x, y, z;
  uint3() : x(0), y(0), z(0) {}
  explicit uint3(uint a) : x(a), y(a), z(a) {}
  explicit uint3(const uint (&a)[3]) : x(a[0]), y(a[1]), z(a[2]) {}  // from an array, as LiteMath's
  explicit uint3(const float3& v);  // componentwise conversion
  explicit uint3(const int3& v);  // componentwise conversion
  uint3(uint a_x, uint a_y, uint a_z) : x(a_x), y(a_y), z(a_z) {}
  uint3(uint2 v, uint a_z) : x(v.x), y(v.y), z(a_z) {}
  uint&       operator[](int i) { return (&x)[i]; }
  const uint& operator[](int i) const { return (&x)[i]; }
};

struct alignas(16) uint4
{
  uint x, y, z, w;
  uint4() : x(0), y(0), z(0), w(0) {}
  explicit uint4(uint a) : x(a), y(a), z(a), w(a) {}
  explicit uint4(const uint (&a)[4]) : x(a[0]), y(a[1]), z(a[2]), w(a[3]) {}  // from an array, as LiteMath's
  explicit uint4(const float4& v);  // componentwise conversion
  explicit uint4(const int4& v);  // componentwise conversion
  uint4(uint a_x, uint a_y, uint a_z, uint a_w) : x(a_x), y(a_y), z(a_z), w(a_w) {}
  uint4(uint3 v, uint a_w) : x(v.x), y(v.y), z(v.z), w(a_w) {}
  uint&       operator[](int i) { return (&x)[i]; }
  const uint& operator[](int i) const { return (&x)[i]; }
};

// The GPU side relies on these layouts (std430-compatible for the 2/4-wide types).
static_assert(sizeof(float2) == 8 && alignof(float2) == 8, "float2 layout");
static_assert(sizeof(float3) == 12 && alignof(float3) == 4, "float3 layout");
static_assert(sizeof(float4) == 16 && alignof(float4) == 16, "float4 layout");
static_assert(sizeof(int2) == 8 && alignof(int2) == 8, "int2 layout");
static_assert(sizeof(int3) == 12 && alignof(int3) == 4, "int3 layout");
static_assert(sizeof(int4) == 16 && alignof(int4) == 16, "int4 layout");
static_assert(sizeof(uint2) == 8 && alignof(uint2) == 8, "uint2 layout");
static_assert(sizeof(uint3) == 12 && alignof(uint3) == 4, "uint3 layout");
static_assert(sizeof(uint4) == 16 && alignof(uint4) == 16, "uint4 layout");

// ---------------------------------------------------------------- make_* constructors
inline float2 make_float2(float x, float y) { return float2(x, y); }
inline float3 make_float3(float x, float y, float z) { return float3(x, y, z); }
inline float4 make_float4(float x, float y, float z, float w) { return float4(x, y, z, w); }
inline int2   make_int2(int x, int y) { return int2(x, y); }
inline int3   make_int3(int x, int y, int z) { return int3(x, y, z); }
inline int4   make_int4(int x, int y, int z, int w) { return int4(x, y, z, w); }
inline uint2  make_uint2(uint x, uint y) { return uint2(x, y); }
inline uint3  make_uint3(uint x, uint y, uint z) { return uint3(x, y, z); }
inline uint4  make_uint4(uint x, uint y, uint z, uint w) { return uint4(x, y, z, w); }

// ---------------------------------------------------------------- arithmetic operators
// Macros generate the same componentwise operator set for every vector type; they are
// #undef'd at the end of the header.

#define LM_VEC2_BINOP(V, S, OP)                                                              \
  inline V operator OP(const V& a, const V& b) { return V(a.x OP b.x, a.y OP b.y); }         \
  inline V operator OP(const V& a, S b) { return V(a.x OP b, a.y OP b); }                    \
  inline V operator OP(S a, const V& b) { return V(a OP b.x, a OP b.y); }                    \
  inline V& operator OP##=(V& a, const V& b) { a.x OP## = b.x; a.y OP## = b.y; return a; }   \
  inline V& operator OP##=(V& a, S b) { a.x OP## = b; a.y OP## = b; return a; }

#define LM_VEC3_BINOP(V, S, OP)                                                              \
  inline V operator OP(const V& a, const V& b) { return V(a.x OP b.x, a.y OP b.y, a.z OP b.z); } \
  inline V operator OP(const V& a, S b) { return V(a.x OP b, a.y OP b, a.z OP b); }          \
  inline V operator OP(S a, const V& b) { return V(a OP b.x, a OP b.y, a OP b.z); }          \
  inline V& operator OP##=(V& a, const V& b) { a.x OP## = b.x; a.y OP## = b.y; a.z OP## = b.z; return a; } \
  inline V& operator OP##=(V& a, S b) { a.x OP## = b; a.y OP## = b; a.z OP## = b; return a; }

#define LM_VEC4_BINOP(V, S, OP)                                                              \
  inline V operator OP(const V& a, const V& b) { return V(a.x OP b.x, a.y OP b.y, a.z OP b.z, a.w OP b.w); } \
  inline V operator OP(const V& a, S b) { return V(a.x OP b, a.y OP b, a.z OP b, a.w OP b); } \
  inline V operator OP(S a, const V& b) { return V(a OP b.x, a OP b.y, a OP b.z, a OP b.w); } \
  inline V& operator OP##=(V& a, const V& b) { a.x OP## = b.x; a.y OP## = b.y; a.z OP## = b.z; a.w OP## = b.w; return a; } \
  inline V& operator OP##=(V& a, S b) { a.x OP## = b; a.y OP## = b; a.z OP## = b; a.w OP## = b; return a; }

#define LM_VEC_ARITH(DIM, V, S) \
  LM_VEC##DIM##_BINOP(V, S, +) LM_VEC##DIM##_BINOP(V, S, -) LM_VEC##DIM##_BINOP(V, S, *) LM_VEC##DIM##_BINOP(V, S, /)

LM_VEC_ARITH(2, float2, float)
LM_VEC_ARITH(3, float3, float)
#if LITEMATH_FLOAT4_SSE
inline __m128 lm_load(const float4& a) { return _mm_load_ps(&a.x); }
inline float4 lm_store(__m128 v)
{
  float4 r;
  _mm_store_ps(&r.x, v);
  return r;
}
#define LM_FLOAT4_SSE_OP(OP, INTRIN)                                                           \
  inline float4 operator OP(const float4& a, const float4& b) { return lm_store(INTRIN(lm_load(a), lm_load(b))); } \
  inline float4 operator OP(const float4& a, float b) { return lm_store(INTRIN(lm_load(a), _mm_set1_ps(b))); } \
  inline float4 operator OP(float a, const float4& b) { return lm_store(INTRIN(_mm_set1_ps(a), lm_load(b))); } \
  inline float4& operator OP##=(float4& a, const float4& b) { return a = a OP b; }            \
  inline float4& operator OP##=(float4& a, float b) { return a = a OP b; }
LM_FLOAT4_SSE_OP(+, _mm_add_ps)
LM_FLOAT4_SSE_OP(-, _mm_sub_ps)
LM_FLOAT4_SSE_OP(*, _mm_mul_ps)
LM_FLOAT4_SSE_OP(/, _mm_div_ps)
#undef LM_FLOAT4_SSE_OP
#else
LM_VEC_ARITH(4, float4, float)
#endif
LM_VEC_ARITH(2, int2, int)
LM_VEC_ARITH(3, int3, int)
LM_VEC_ARITH(4, int4, int)
LM_VEC_ARITH(2, uint2, uint)
LM_VEC_ARITH(3, uint3, uint)
LM_VEC_ARITH(4, uint4, uint)

inline float2 operator-(const float2& a) { return float2(-a.x, -a.y); }
inline float3 operator-(const float3& a) { return float3(-a.x, -a.y, -a.z); }
inline float4 operator-(const float4& a) { return float4(-a.x, -a.y, -a.z, -a.w); }
inline int2   operator-(const int2& a) { return int2(-a.x, -a.y); }
inline int3   operator-(const int3& a) { return int3(-a.x, -a.y, -a.z); }
inline int4   operator-(const int4& a) { return int4(-a.x, -a.y, -a.z, -a.w); }

// ---------------------------------------------------------------- componentwise functions
#define LM_UNARY2(V, NAME, F) inline V NAME(const V& a) { return V(F(a.x), F(a.y)); }
#define LM_UNARY3(V, NAME, F) inline V NAME(const V& a) { return V(F(a.x), F(a.y), F(a.z)); }
#define LM_UNARY4(V, NAME, F) inline V NAME(const V& a) { return V(F(a.x), F(a.y), F(a.z), F(a.w)); }
#define LM_BINARY2(V, NAME, F) inline V NAME(const V& a, const V& b) { return V(F(a.x, b.x), F(a.y, b.y)); }
#define LM_BINARY3(V, NAME, F) inline V NAME(const V& a, const V& b) { return V(F(a.x, b.x), F(a.y, b.y), F(a.z, b.z)); }
#define LM_BINARY4(V, NAME, F) inline V NAME(const V& a, const V& b) { return V(F(a.x, b.x), F(a.y, b.y), F(a.z, b.z), F(a.w, b.w)); }

// Functions shared by all vector types of one width: min, max, clamp.
#define LM_MINMAX(DIM, V, S)                                                                   \
  LM_BINARY##DIM(V, min, std::min) LM_BINARY##DIM(V, max, std::max)                              \
  inline V clamp(const V& x, const V& lo, const V& hi) { return min(max(x, lo), hi); }       \
  inline V clamp(const V& x, S lo, S hi) { return min(max(x, V(lo)), V(hi)); }

// Float-only functions.
#define LM_FLOAT_FUNCS(DIM, V)                                                                 \
  LM_UNARY##DIM(V, abs, std::abs) LM_UNARY##DIM(V, floor, std::floor)                            \
  LM_UNARY##DIM(V, ceil, std::ceil) LM_UNARY##DIM(V, fract, fract) LM_UNARY##DIM(V, sign, sign)    \
  LM_UNARY##DIM(V, sqrt, std::sqrt) LM_UNARY##DIM(V, inversesqrt, inversesqrt)                   \
  LM_UNARY##DIM(V, sin, std::sin) LM_UNARY##DIM(V, cos, std::cos)                                \
  LM_UNARY##DIM(V, exp, std::exp) LM_UNARY##DIM(V, log, std::log)                                \
  LM_BINARY##DIM(V, pow, std::pow) LM_BINARY##DIM(V, step, step)                                 \
  inline V step(float edge, const V& x) { return step(V(edge), x); }                         \
  inline V lerp(const V& a, const V& b, float t) { return a + t * (b - a); }                 \
  inline V mix(const V& a, const V& b, float t) { return a + t * (b - a); }                  \
  inline V mix(const V& a, const V& b, const V& t) { return a + t * (b - a); }               \
  inline V smoothstep(float e0, float e1, const V& x)                                        \
  {                                                                                          \
    const V t = clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);                                     \
    return t * t * (3.0f - 2.0f * t);                                                        \
  }                                                                                          \
  inline float length(const V& a) { return std::sqrt(dot(a, a)); }                           \
  inline float distance(const V& a, const V& b) { return length(a - b); }                    \
  inline V normalize(const V& a) { return a * (1.0f / length(a)); }                          \
  inline V reflect(const V& I, const V& N) { return I - 2.0f * dot(N, I) * N; }              \
  inline V refract(const V& I, const V& N, float eta)                                        \
  {                                                                                          \
    /* GLSL semantics: zero vector on total internal reflection */                           \
    const float d = dot(N, I);                                                               \
    const float k = 1.0f - eta * eta * (1.0f - d * d);                                       \
    if (k < 0.0f)                                                                            \
      return V(0.0f);                                                                        \
    return eta * I - (eta * d + std::sqrt(k)) * N;                                           \
  }

inline float dot(const float2& a, const float2& b) { return a.x * b.x + a.y * b.y; }
inline float dot(const float3& a, const float3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline float dot(const float4& a, const float4& b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }
inline int   dot(const int2& a, const int2& b) { return a.x * b.x + a.y * b.y; }
inline int   dot(const int3& a, const int3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline int   dot(const int4& a, const int4& b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }
inline uint  dot(const uint2& a, const uint2& b) { return a.x * b.x + a.y * b.y; }
inline uint  dot(const uint3& a, const uint3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline uint  dot(const uint4& a, const uint4& b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }

inline float3 cross(const float3& a, const float3& b)
{
  return float3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

LM_MINMAX(2, float2, float)
LM_MINMAX(3, float3, float)
#if LITEMATH_FLOAT4_SSE
// std::min(a, b) is (b < a ? b : a), which is _mm_min_ps(b, a), NaNs included; max likewise.
inline float4 min(const float4& a, const float4& b) { return lm_store(_mm_min_ps(lm_load(b), lm_load(a))); }
inline float4 max(const float4& a, const float4& b) { return lm_store(_mm_max_ps(lm_load(b), lm_load(a))); }
inline float4 clamp(const float4& x, const float4& lo, const float4& hi) { return min(max(x, lo), hi); }
inline float4 clamp(const float4& x, float lo, float hi) { return min(max(x, float4(lo)), float4(hi)); }
#else
LM_MINMAX(4, float4, float)
#endif
LM_FLOAT_FUNCS(2, float2)
LM_FLOAT_FUNCS(3, float3)
LM_FLOAT_FUNCS(4, float4)

inline int iabs_(int x) { return x < 0 ? -x : x; }
LM_MINMAX(2, int2, int)
LM_MINMAX(3, int3, int)
LM_MINMAX(4, int4, int)
LM_UNARY2(int2, abs, iabs_)
LM_UNARY3(int3, abs, iabs_)
LM_UNARY4(int4, abs, iabs_)
LM_UNARY2(int2, sign, sign)
LM_UNARY3(int3, sign, sign)
LM_UNARY4(int4, sign, sign)
LM_MINMAX(2, uint2, uint)
LM_MINMAX(3, uint3, uint)
LM_MINMAX(4, uint4, uint)

// Horizontal min/max over the components.
inline float hmin(const float3& a) { return std::min(a.x, std::min(a.y, a.z)); }
inline float hmax(const float3& a) { return std::max(a.x, std::max(a.y, a.z)); }
inline float hmin(const float4& a) { return std::min(std::min(a.x, a.y), std::min(a.z, a.w)); }
inline float hmax(const float4& a) { return std::max(std::max(a.x, a.y), std::max(a.z, a.w)); }

// Bit i set where a[i] <= b[i] (a NaN on either side compares false): one SIMD compare on the
// CPU, and lessThanEqual on the GPU. For branching on which of four lanes pass a test.
#if LITEMATH_FLOAT4_SSE
inline uint lane_mask_le(const float4& a, const float4& b) { return uint(_mm_movemask_ps(_mm_cmple_ps(lm_load(a), lm_load(b)))); }
#else
inline uint lane_mask_le(const float4& a, const float4& b)
{
  return (a.x <= b.x ? 1u : 0u) | (a.y <= b.y ? 2u : 0u) | (a.z <= b.z ? 4u : 0u) | (a.w <= b.w ? 8u : 0u);
}
#endif

// ---------------------------------------------------------------- conversions
inline float2 to_float2(const float3& v) { return float2(v.x, v.y); }
inline float2 to_float2(const float4& v) { return float2(v.x, v.y); }
inline float3 to_float3(const float4& v) { return float3(v.x, v.y, v.z); }
inline float4 to_float4(const float3& v, float w) { return float4(v.x, v.y, v.z, w); }

// Numeric (value-converting) casts, like GLSL vec3(ivec3).
inline float2 to_float2(const int2& v) { return float2(float(v.x), float(v.y)); }
inline float3 to_float3(const int3& v) { return float3(float(v.x), float(v.y), float(v.z)); }
inline float4 to_float4(const int4& v) { return float4(float(v.x), float(v.y), float(v.z), float(v.w)); }
inline float2 to_float2(const uint2& v) { return float2(float(v.x), float(v.y)); }
inline float3 to_float3(const uint3& v) { return float3(float(v.x), float(v.y), float(v.z)); }
inline float4 to_float4(const uint4& v) { return float4(float(v.x), float(v.y), float(v.z), float(v.w)); }
inline int2   to_int2(const float2& v) { return int2(int(v.x), int(v.y)); }
inline int3   to_int3(const float3& v) { return int3(int(v.x), int(v.y), int(v.z)); }
inline int4   to_int4(const float4& v) { return int4(int(v.x), int(v.y), int(v.z), int(v.w)); }
inline uint2  to_uint2(const float2& v) { return uint2(uint(v.x), uint(v.y)); }
inline uint3  to_uint3(const float3& v) { return uint3(uint(v.x), uint(v.y), uint(v.z)); }
inline uint4  to_uint4(const float4& v) { return uint4(uint(v.x), uint(v.y), uint(v.z), uint(v.w)); }

// Converting constructors (explicit, as in the paper's LiteMath): C conversions per component, so
// int2(float2(-1.5f, 2.7f)) is (-1, 2), as GLSL's ivec2(vec2) truncates.
inline float2::float2(const int2& v) : x(float(v.x)), y(float(v.y)) {}
inline float2::float2(const uint2& v) : x(float(v.x)), y(float(v.y)) {}
inline float3::float3(const int3& v) : x(float(v.x)), y(float(v.y)), z(float(v.z)) {}
inline float3::float3(const uint3& v) : x(float(v.x)), y(float(v.y)), z(float(v.z)) {}
inline float4::float4(const int4& v) : x(float(v.x)), y(float(v.y)), z(float(v.z)), w(float(v.w)) {}
inline float4::float4(const uint4& v) : x(float(v.x)), y(float(v.y)), z(float(v.z)), w(float(v.w)) {}
inline int2::int2(const float2& v) : x(int(v.x)), y(int(v.y)) {}
inline int2::int2(const uint2& v) : x(int(v.x)), y(int(v.y)) {}
inline int3::int3(const float3& v) : x(int(v.x)), y(int(v.y)), z(int(v.z)) {}
inline int3::int3(const uint3& v) : x(int(v.x)), y(int(v.y)), z(int(v.z)) {}
inline int4::int4(const float4& v) : x(int(v.x)), y(int(v.y)), z(int(v.z)), w(int(v.w)) {}
inline int4::int4(const uint4& v) : x(int(v.x)), y(int(v.y)), z(int(v.z)), w(int(v.w)) {}
inline uint2::uint2(const float2& v) : x(uint(v.x)), y(uint(v.y)) {}
inline uint2::uint2(const int2& v) : x(uint(v.x)), y(uint(v.y)) {}
inline uint3::uint3(const float3& v) : x(uint(v.x)), y(uint(v.y)), z(uint(v.z)) {}
inline uint3::uint3(const int3& v) : x(uint(v.x)), y(uint(v.y)), z(uint(v.z)) {}
inline uint4::uint4(const float4& v) : x(uint(v.x)), y(uint(v.y)), z(uint(v.z)), w(uint(v.w)) {}
inline uint4::uint4(const int4& v) : x(uint(v.x)), y(uint(v.y)), z(uint(v.z)), w(uint(v.w)) {}

// Width changes as the paper's LiteMath has them: to_int4(int3, w) appends w; to_int3(int4) drops it.
inline int4  to_int4(const int3& v, int w) { return int4(v.x, v.y, v.z, w); }
inline uint4 to_uint4(const uint3& v, uint w) { return uint4(v.x, v.y, v.z, w); }
inline int3  to_int3(const int4& v) { return int3(v.x, v.y, v.z); }
inline uint3 to_uint3(const uint4& v) { return uint3(v.x, v.y, v.z); }

// ---------------------------------------------------------------- bit casts (memcpy: no aliasing UB)
inline int as_int(float x) { int r; std::memcpy(&r, &x, sizeof(r)); return r; }
inline uint as_uint(float x) { uint r; std::memcpy(&r, &x, sizeof(r)); return r; }
inline float as_float(int x) { float r; std::memcpy(&r, &x, sizeof(r)); return r; }
inline float as_float(uint x) { float r; std::memcpy(&r, &x, sizeof(r)); return r; }
inline int4 as_int(const float4& v) { return int4(as_int(v.x), as_int(v.y), as_int(v.z), as_int(v.w)); }
inline uint4 as_uint(const float4& v) { return uint4(as_uint(v.x), as_uint(v.y), as_uint(v.z), as_uint(v.w)); }
inline float4 as_float(const int4& v) { return float4(as_float(v.x), as_float(v.y), as_float(v.z), as_float(v.w)); }
inline float4 as_float(const uint4& v) { return float4(as_float(v.x), as_float(v.y), as_float(v.z), as_float(v.w)); }

// ---------------------------------------------------------------- float3x3
// Column-major: m_col[i] is column i. The 9-float constructor takes values in ROW-MAJOR
// reading order, i.e. as the matrix is written on paper.
struct float3x3
{
  float3 m_col[3];

  float3x3() // identity
  {
    m_col[0] = float3(1, 0, 0);
    m_col[1] = float3(0, 1, 0);
    m_col[2] = float3(0, 0, 1);
  }
  float3x3(float m00, float m01, float m02, //
           float m10, float m11, float m12, //
           float m20, float m21, float m22)
  {
    m_col[0] = float3(m00, m10, m20);
    m_col[1] = float3(m01, m11, m21);
    m_col[2] = float3(m02, m12, m22);
  }

  float3&       operator[](int i) { return m_col[i]; } // column i, like GLSL
  const float3& operator[](int i) const { return m_col[i]; }
  float&        operator()(int row, int col) { return m_col[col][row]; }
  float         operator()(int row, int col) const { return m_col[col][row]; }

  float3 get_col(int i) const { return m_col[i]; }
  void   set_col(int i, const float3& v) { m_col[i] = v; }
  float3 get_row(int i) const { return float3(m_col[0][i], m_col[1][i], m_col[2][i]); }
  void   set_row(int i, const float3& v) { m_col[0][i] = v.x; m_col[1][i] = v.y; m_col[2][i] = v.z; }
};

inline float3 operator*(const float3x3& m, const float3& v)
{
  return m.m_col[0] * v.x + m.m_col[1] * v.y + m.m_col[2] * v.z;
}
inline float3x3 operator*(const float3x3& a, const float3x3& b)
{
  float3x3 r;
  for (int i = 0; i < 3; i++)
    r.m_col[i] = a * b.m_col[i];
  return r;
}
inline float3x3 operator*(const float3x3& m, float s)
{
  float3x3 r;
  for (int i = 0; i < 3; i++)
    r.m_col[i] = m.m_col[i] * s;
  return r;
}
inline float3x3 operator*(float s, const float3x3& m) { return m * s; }

inline float3x3 transpose(const float3x3& m)
{
  float3x3 r;
  for (int i = 0; i < 3; i++)
    r.set_row(i, m.m_col[i]);
  return r;
}
inline float determinant(const float3x3& m)
{
  // Scalar triple product of the columns.
  return dot(m.m_col[0], cross(m.m_col[1], m.m_col[2]));
}
inline float3x3 inverse(const float3x3& m)
{
  // Rows of the inverse are the cross products of column pairs divided by the determinant.
  const float3 r0 = cross(m.m_col[1], m.m_col[2]);
  const float3 r1 = cross(m.m_col[2], m.m_col[0]);
  const float3 r2 = cross(m.m_col[0], m.m_col[1]);
  const float  invDet = 1.0f / dot(m.m_col[0], r0);
  float3x3     r;
  r.set_row(0, r0 * invDet);
  r.set_row(1, r1 * invDet);
  r.set_row(2, r2 * invDet);
  return r;
}

// ---------------------------------------------------------------- float4x4
// Column-major: m_col[i] is column i (so the 16 floats in memory are column-major, matching
// GLSL mat4 and RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR). The 16-float constructor takes values in
// ROW-MAJOR reading order, i.e. as the matrix is written on paper.
struct alignas(16) float4x4
{
  float4 m_col[4];

  float4x4() // identity
  {
    m_col[0] = float4(1, 0, 0, 0);
    m_col[1] = float4(0, 1, 0, 0);
    m_col[2] = float4(0, 0, 1, 0);
    m_col[3] = float4(0, 0, 0, 1);
  }
  float4x4(float m00, float m01, float m02, float m03, //
           float m10, float m11, float m12, float m13, //
           float m20, float m21, float m22, float m23, //
           float m30, float m31, float m32, float m33)
  {
    m_col[0] = float4(m00, m10, m20, m30);
    m_col[1] = float4(m01, m11, m21, m31);
    m_col[2] = float4(m02, m12, m22, m32);
    m_col[3] = float4(m03, m13, m23, m33);
  }

  float4&       operator[](int i) { return m_col[i]; } // column i, like GLSL
  const float4& operator[](int i) const { return m_col[i]; }
  float&        operator()(int row, int col) { return m_col[col][row]; }
  float         operator()(int row, int col) const { return m_col[col][row]; }

  float4 get_col(int i) const { return m_col[i]; }
  void   set_col(int i, const float4& v) { m_col[i] = v; }
  float4 get_row(int i) const { return float4(m_col[0][i], m_col[1][i], m_col[2][i], m_col[3][i]); }
  void   set_row(int i, const float4& v)
  {
    m_col[0][i] = v.x; m_col[1][i] = v.y; m_col[2][i] = v.z; m_col[3][i] = v.w;
  }
};
static_assert(sizeof(float4x4) == 64 && alignof(float4x4) == 16, "float4x4 layout");
static_assert(sizeof(float3x3) == 36, "float3x3 layout");

inline float4 operator*(const float4x4& m, const float4& v)
{
  return m.m_col[0] * v.x + m.m_col[1] * v.y + m.m_col[2] * v.z + m.m_col[3] * v.w;
}
inline float4x4 operator*(const float4x4& a, const float4x4& b)
{
  float4x4 r;
  for (int i = 0; i < 4; i++)
    r.m_col[i] = a * b.m_col[i];
  return r;
}
inline float4x4 operator*(const float4x4& m, float s)
{
  float4x4 r;
  for (int i = 0; i < 4; i++)
    r.m_col[i] = m.m_col[i] * s;
  return r;
}
inline float4x4 operator*(float s, const float4x4& m) { return m * s; }

inline float4x4 transpose(const float4x4& m)
{
  float4x4 r;
  for (int i = 0; i < 4; i++)
    r.set_row(i, m.m_col[i]);
  return r;
}

// Helpers that users' code often defines itself (the paper's samples carry their own copies of
// mul4x3, mul3x3, lookAt and perspectiveMatrix): templates with a defaulted parameter, so that a
// user's plain function of the same name and parameters is preferred instead of ambiguous.
#define LITEMATH_YIELDS_TO_USER template <int LiteMathYieldsToUser = 0>

// Point transform (w = 1) and direction transform (w = 0, translation ignored).
LITEMATH_YIELDS_TO_USER inline float3 mul4x3(const float4x4& m, const float3& p)
{
  return to_float3(m.m_col[0] * p.x + m.m_col[1] * p.y + m.m_col[2] * p.z + m.m_col[3]);
}
LITEMATH_YIELDS_TO_USER inline float3 mul3x3(const float4x4& m, const float3& d)
{
  return to_float3(m.m_col[0] * d.x + m.m_col[1] * d.y + m.m_col[2] * d.z);
}

inline float determinant(const float4x4& m)
{
  // Laplace expansion via 2x2 sub-determinants of the upper and lower row pairs.
  const float a[4][4] = {{m(0, 0), m(0, 1), m(0, 2), m(0, 3)},
                         {m(1, 0), m(1, 1), m(1, 2), m(1, 3)},
                         {m(2, 0), m(2, 1), m(2, 2), m(2, 3)},
                         {m(3, 0), m(3, 1), m(3, 2), m(3, 3)}};
  const float s0 = a[0][0] * a[1][1] - a[1][0] * a[0][1];
  const float s1 = a[0][0] * a[1][2] - a[1][0] * a[0][2];
  const float s2 = a[0][0] * a[1][3] - a[1][0] * a[0][3];
  const float s3 = a[0][1] * a[1][2] - a[1][1] * a[0][2];
  const float s4 = a[0][1] * a[1][3] - a[1][1] * a[0][3];
  const float s5 = a[0][2] * a[1][3] - a[1][2] * a[0][3];
  const float c5 = a[2][2] * a[3][3] - a[3][2] * a[2][3];
  const float c4 = a[2][1] * a[3][3] - a[3][1] * a[2][3];
  const float c3 = a[2][1] * a[3][2] - a[3][1] * a[2][2];
  const float c2 = a[2][0] * a[3][3] - a[3][0] * a[2][3];
  const float c1 = a[2][0] * a[3][2] - a[3][0] * a[2][2];
  const float c0 = a[2][0] * a[3][1] - a[3][0] * a[2][1];
  return s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0;
}

// General 4x4 inverse (adjugate / determinant, same 2x2 sub-determinant scheme as above).
inline float4x4 inverse4x4(const float4x4& m)
{
  const float a[4][4] = {{m(0, 0), m(0, 1), m(0, 2), m(0, 3)},
                         {m(1, 0), m(1, 1), m(1, 2), m(1, 3)},
                         {m(2, 0), m(2, 1), m(2, 2), m(2, 3)},
                         {m(3, 0), m(3, 1), m(3, 2), m(3, 3)}};
  const float s0 = a[0][0] * a[1][1] - a[1][0] * a[0][1];
  const float s1 = a[0][0] * a[1][2] - a[1][0] * a[0][2];
  const float s2 = a[0][0] * a[1][3] - a[1][0] * a[0][3];
  const float s3 = a[0][1] * a[1][2] - a[1][1] * a[0][2];
  const float s4 = a[0][1] * a[1][3] - a[1][1] * a[0][3];
  const float s5 = a[0][2] * a[1][3] - a[1][2] * a[0][3];
  const float c5 = a[2][2] * a[3][3] - a[3][2] * a[2][3];
  const float c4 = a[2][1] * a[3][3] - a[3][1] * a[2][3];
  const float c3 = a[2][1] * a[3][2] - a[3][1] * a[2][2];
  const float c2 = a[2][0] * a[3][3] - a[3][0] * a[2][3];
  const float c1 = a[2][0] * a[3][2] - a[3][0] * a[2][2];
  const float c0 = a[2][0] * a[3][1] - a[3][0] * a[2][1];

  const float invDet = 1.0f / (s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0);

  float4x4 r; // r(row, col) written in paper order
  r(0, 0) = (a[1][1] * c5 - a[1][2] * c4 + a[1][3] * c3) * invDet;
  r(0, 1) = (-a[0][1] * c5 + a[0][2] * c4 - a[0][3] * c3) * invDet;
  r(0, 2) = (a[3][1] * s5 - a[3][2] * s4 + a[3][3] * s3) * invDet;
  r(0, 3) = (-a[2][1] * s5 + a[2][2] * s4 - a[2][3] * s3) * invDet;

  r(1, 0) = (-a[1][0] * c5 + a[1][2] * c2 - a[1][3] * c1) * invDet;
  r(1, 1) = (a[0][0] * c5 - a[0][2] * c2 + a[0][3] * c1) * invDet;
  r(1, 2) = (-a[3][0] * s5 + a[3][2] * s2 - a[3][3] * s1) * invDet;
  r(1, 3) = (a[2][0] * s5 - a[2][2] * s2 + a[2][3] * s1) * invDet;

  r(2, 0) = (a[1][0] * c4 - a[1][1] * c2 + a[1][3] * c0) * invDet;
  r(2, 1) = (-a[0][0] * c4 + a[0][1] * c2 - a[0][3] * c0) * invDet;
  r(2, 2) = (a[3][0] * s4 - a[3][1] * s2 + a[3][3] * s0) * invDet;
  r(2, 3) = (-a[2][0] * s4 + a[2][1] * s2 - a[2][3] * s0) * invDet;

  r(3, 0) = (-a[1][0] * c3 + a[1][1] * c1 - a[1][2] * c0) * invDet;
  r(3, 1) = (a[0][0] * c3 - a[0][1] * c1 + a[0][2] * c0) * invDet;
  r(3, 2) = (-a[3][0] * s3 + a[3][1] * s1 - a[3][2] * s0) * invDet;
  r(3, 3) = (a[2][0] * s3 - a[2][1] * s1 + a[2][2] * s0) * invDet;
  return r;
}
inline float4x4 inverse(const float4x4& m) { return inverse4x4(m); }

// ---------------------------------------------------------------- transform builders
inline float4x4 translate4x4(const float3& t)
{
  float4x4 r;
  r.m_col[3] = float4(t.x, t.y, t.z, 1.0f);
  return r;
}
inline float4x4 scale4x4(const float3& s)
{
  float4x4 r;
  r(0, 0) = s.x;
  r(1, 1) = s.y;
  r(2, 2) = s.z;
  return r;
}
// Right-handed rotations by `rad` radians (counter-clockwise looking down the axis to the origin).
inline float4x4 rotate4x4X(float rad)
{
  const float c = std::cos(rad), s = std::sin(rad);
  return float4x4(1, 0, 0, 0,
                  0, c, -s, 0,
                  0, s, c, 0,
                  0, 0, 0, 1);
}
inline float4x4 rotate4x4Y(float rad)
{
  const float c = std::cos(rad), s = std::sin(rad);
  return float4x4(c, 0, s, 0,
                  0, 1, 0, 0,
                  -s, 0, c, 0,
                  0, 0, 0, 1);
}
inline float4x4 rotate4x4Z(float rad)
{
  const float c = std::cos(rad), s = std::sin(rad);
  return float4x4(c, -s, 0, 0,
                  s, c, 0, 0,
                  0, 0, 1, 0,
                  0, 0, 0, 1);
}
// Rotation about an arbitrary axis (need not be normalized), Rodrigues' formula.
inline float4x4 rotate4x4(const float3& axis, float rad)
{
  const float3 a = normalize(axis);
  const float  c = std::cos(rad), s = std::sin(rad), t = 1.0f - c;
  return float4x4(t * a.x * a.x + c,       t * a.x * a.y - s * a.z, t * a.x * a.z + s * a.y, 0,
                  t * a.x * a.y + s * a.z, t * a.y * a.y + c,       t * a.y * a.z - s * a.x, 0,
                  t * a.x * a.z - s * a.y, t * a.y * a.z + s * a.x, t * a.z * a.z + c,       0,
                  0, 0, 0, 1);
}

// OpenGL-style view matrix (right-handed): eye -> origin, camera looks down -Z, up is +Y.
LITEMATH_YIELDS_TO_USER inline float4x4 lookAt(const float3& eye, const float3& center, const float3& up)
{
  const float3 f = normalize(center - eye);
  const float3 s = normalize(cross(f, up));
  const float3 u = cross(s, f);
  return float4x4(s.x, s.y, s.z, -dot(s, eye),
                  u.x, u.y, u.z, -dot(u, eye),
                  -f.x, -f.y, -f.z, dot(f, eye),
                  0, 0, 0, 1);
}

// OpenGL-style projection (gluPerspective): view-space z=-zNear -> NDC z=-1, z=-zFar -> +1.
LITEMATH_YIELDS_TO_USER inline float4x4 perspectiveMatrix(float fovy_degrees, float aspect, float zNear, float zFar)
{
  const float f = 1.0f / std::tan(0.5f * fovy_degrees * DEG_TO_RAD);
  return float4x4(f / aspect, 0, 0, 0,
                  0, f, 0, 0,
                  0, 0, (zFar + zNear) / (zNear - zFar), 2.0f * zFar * zNear / (zNear - zFar),
                  0, 0, -1, 0);
}

// ---------------------------------------------------------------- bounding box
// Axis-aligned box; w components are carried along but ignored by the geometric queries.
struct Box4f
{
  float4 boxMin = float4(INF_POSITIVE); // empty by default: any include() fixes it
  float4 boxMax = float4(INF_NEGATIVE);

  Box4f() = default;
  Box4f(const float4& a_min, const float4& a_max) : boxMin(a_min), boxMax(a_max) {}

  void include(const float4& p)
  {
    boxMin = min(boxMin, p);
    boxMax = max(boxMax, p);
  }
  void include(const Box4f& b)
  {
    boxMin = min(boxMin, b.boxMin);
    boxMax = max(boxMax, b.boxMax);
  }
  float4 center() const { return 0.5f * (boxMin + boxMax); }
  float4 extent() const { return boxMax - boxMin; }
  bool   empty() const { return boxMin.x > boxMax.x || boxMin.y > boxMax.y || boxMin.z > boxMax.z; }
  float  surfaceArea() const
  {
    if (empty())
      return 0.0f;
    const float4 e = extent();
    return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
  int axisOfMaxExtent() const
  {
    const float4 e = extent();
    if (e.x >= e.y && e.x >= e.z)
      return 0;
    return e.y >= e.z ? 1 : 2;
  }
};


// ================================================================ the paper's LiteMath API
// Names and semantics of msu-graphics-group/LiteMath that kernels written for the paper use.

// ---------------------------------------------------------------- scalar and vector helpers
// GLSL's mod: x - y * floor(x / y), the sign of y (not fmod's, the sign of x).
inline float mod(float x, float y) { return x - y * std::floor(x / y); }
inline float2 mod(const float2& x, const float2& y) { return x - y * floor(x / y); }
inline float3 mod(const float3& x, const float3& y) { return x - y * floor(x / y); }
inline float4 mod(const float4& x, const float4& y) { return x - y * floor(x / y); }
inline float rcp(float x) { return 1.0f / x; }
inline float2 rcp(const float2& v) { return float2(1.0f) / v; }
inline float3 rcp(const float3& v) { return float3(1.0f) / v; }
inline float4 rcp(const float4& v) { return float4(1.0f) / v; }
template <typename T> inline T SQR(T x) { return x * x; }
inline float3 faceforward(const float3& n, const float3& i, const float3& ng) { return dot(i, ng) < 0.0f ? n : -n; }
inline float hmin(const float2& a) { return std::min(a.x, a.y); }
inline float hmax(const float2& a) { return std::max(a.x, a.y); }
inline float hmin3(const float4& a) { return std::min(a.x, std::min(a.y, a.z)); }
inline float hmax3(const float4& a) { return std::max(a.x, std::max(a.y, a.z)); }

// float4 as a 3-vector plus w: the xyz part's dot product, length, cross product (w = 0) and
// normalisation (all four components divided by the xyz length).
inline float  dot3(const float4& a, const float4& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline float  dot4(const float4& a, const float4& b) { return dot(a, b); }
inline float  dot3f(const float4& a, const float4& b) { return dot3(a, b); }
inline float  dot4f(const float4& a, const float4& b) { return dot(a, b); }
inline float4 dot3v(const float4& a, const float4& b) { return float4(dot3(a, b)); }
inline float4 dot4v(const float4& a, const float4& b) { return float4(dot(a, b)); }
inline float  length3(const float4& a) { return std::sqrt(dot3(a, a)); }
inline float  length3f(const float4& a) { return length3(a); }
inline float  length4(const float4& a) { return length(a); }
inline float  length4f(const float4& a) { return length(a); }
inline float4 length3v(const float4& a) { return float4(length3(a)); }
inline float4 length4v(const float4& a) { return float4(length(a)); }
inline float4 normalize3(const float4& a) { return a / length3(a); }
inline float4 cross3(const float4& a, const float4& b)
{
  return float4(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x, 0.0f);
}
inline float4 cross(const float4& a, const float4& b) { return cross3(a, b); }

// ---------------------------------------------------------------- matrices
inline float4 mul4x4x4(const float4x4& m, const float4& v) { return m * v; }
inline float4 mul(const float4x4& m, const float4& v) { return m * v; }
// A point: (m * (v, 1)).xyz, without a perspective divide.
inline float3 operator*(const float4x4& m, const float3& v) { return to_float3(m * float4(v.x, v.y, v.z, 1.0f)); }
inline float3 mul(const float4x4& m, const float3& v) { return m * v; }
inline float4x4 mul(const float4x4& a, const float4x4& b) { return a * b; }
inline float3 mul(const float3x3& m, const float3& v) { return m * v; }
inline float3x3 mul(const float3x3& a, const float3x3& b) { return a * b; }
inline float4x4 operator+(const float4x4& a, const float4x4& b)
{
  float4x4 r;
  for (int i = 0; i < 4; i++)
    r.m_col[i] = a.m_col[i] + b.m_col[i];
  return r;
}
inline float4x4 operator-(const float4x4& a, const float4x4& b)
{
  float4x4 r;
  for (int i = 0; i < 4; i++)
    r.m_col[i] = a.m_col[i] - b.m_col[i];
  return r;
}
inline float3x3 operator+(const float3x3& a, const float3x3& b)
{
  float3x3 r;
  for (int i = 0; i < 3; i++)
    r.m_col[i] = a.m_col[i] + b.m_col[i];
  return r;
}
inline float3x3 operator-(const float3x3& a, const float3x3& b)
{
  float3x3 r;
  for (int i = 0; i < 3; i++)
    r.m_col[i] = a.m_col[i] - b.m_col[i];
  return r;
}
inline float4x4 make_float4x4_from_rows(const float4& a, const float4& b, const float4& c, const float4& d)
{
  float4x4 m;
  m.set_row(0, a);
  m.set_row(1, b);
  m.set_row(2, c);
  m.set_row(3, d);
  return m;
}
inline float4x4 make_float4x4_from_cols(const float4& a, const float4& b, const float4& c, const float4& d)
{
  float4x4 m;
  m.set_col(0, a);
  m.set_col(1, b);
  m.set_col(2, c);
  m.set_col(3, d);
  return m;
}
inline float3x3 make_float3x3_from_rows(const float3& a, const float3& b, const float3& c)
{
  float3x3 m;
  m.set_row(0, a);
  m.set_row(1, b);
  m.set_row(2, c);
  return m;
}
inline float3x3 make_float3x3_from_cols(const float3& a, const float3& b, const float3& c)
{
  float3x3 m;
  m.set_col(0, a);
  m.set_col(1, b);
  m.set_col(2, c);
  return m;
}
// The paper's older names: make_float3x3 takes rows, make_float3x3_by_columns columns.
inline float3x3 make_float3x3(const float3& a, const float3& b, const float3& c) { return make_float3x3_from_rows(a, b, c); }
inline float3x3 make_float3x3_by_columns(const float3& a, const float3& b, const float3& c) { return make_float3x3_from_cols(a, b, c); }
inline float4x4 outerProduct(const float4& a, const float4& b) { return make_float4x4_from_cols(a * b.x, a * b.y, a * b.z, a * b.w); }
inline float3x3 outerProduct(const float3& a, const float3& b) { return make_float3x3_from_cols(a * b.x, a * b.y, a * b.z); }
inline float3x3 inverse3x3(const float3x3& m) { return inverse(m); }
inline float3x3 scale3x3(const float3& s) { return make_float3x3_from_cols(float3(s.x, 0, 0), float3(0, s.y, 0), float3(0, 0, s.z)); }
// Right-handed rotations by `rad` radians, the upper 3x3 of rotate4x4X/Y/Z.
inline float3x3 rotate3x3X(float rad)
{
  const float c = std::cos(rad), s = std::sin(rad);
  return float3x3(1, 0, 0,
                  0, c, -s,
                  0, s, c);
}
inline float3x3 rotate3x3Y(float rad)
{
  const float c = std::cos(rad), s = std::sin(rad);
  return float3x3(c, 0, s,
                  0, 1, 0,
                  -s, 0, c);
}
inline float3x3 rotate3x3Z(float rad)
{
  const float c = std::cos(rad), s = std::sin(rad);
  return float3x3(c, -s, 0,
                  s, c, 0,
                  0, 0, 1);
}
// glOrtho's projection.
LITEMATH_YIELDS_TO_USER inline float4x4 ortoMatrix(float l, float r, float b, float t, float n, float f)
{
  return float4x4(2.0f / (r - l), 0, 0, -(r + l) / (r - l),
                  0, 2.0f / (t - b), 0, -(t + b) / (t - b),
                  0, 0, -2.0f / (f - n), -(f + n) / (f - n),
                  0, 0, 0, 1);
}

// ---------------------------------------------------------------- half: 16-bit floats for storage
// half converts to and from float implicitly (round to nearest even, infinities and NaN kept);
// half2 and half4 hold two and four, for buffers of compact colours and normals. Arithmetic happens
// in float: to_float4(h), float4(h).
struct half
{
  uint16_t bits = 0;
  half() = default;
  half(float f) : bits(FromFloat(f)) {}
  operator float() const { return ToFloat(bits); }

  static uint16_t FromFloat(float f)
  {
    uint32_t x;
    std::memcpy(&x, &f, 4);
    const uint32_t sign = (x >> 16) & 0x8000u, absBits = x & 0x7FFFFFFFu;
    if (absBits >= 0x7F800000u)  // infinity or NaN (a quiet NaN stays a NaN)
      return uint16_t(sign | 0x7C00u | (absBits > 0x7F800000u ? 0x200u : 0u));
    if (absBits >= 0x477FF000u)  // rounds to beyond 65504: infinity
      return uint16_t(sign | 0x7C00u);
    if (absBits < 0x38800000u)  // a half subnormal (or zero): round the value to a multiple of 2^-24
    {
      float a;
      const uint32_t plain = absBits;
      std::memcpy(&a, &plain, 4);
      return uint16_t(sign | uint32_t(std::nearbyint(a * 16777216.0f)));
    }
    const uint32_t mantissaOdd = (absBits >> 13) & 1u;  // round to nearest, ties to even
    return uint16_t(sign | ((absBits + 0xFFFu + mantissaOdd - 0x38000000u) >> 13));
  }
  static float ToFloat(uint16_t h)
  {
    const uint32_t sign = uint32_t(h & 0x8000u) << 16, exponent = (h >> 10) & 0x1Fu, mantissa = h & 0x3FFu;
    float f;
    if (exponent == 0)
      f = float(mantissa) * (1.0f / 16777216.0f);  // subnormal or zero
    else if (exponent == 31)
    {
      const uint32_t bits = 0x7F800000u | (mantissa << 13);
      std::memcpy(&f, &bits, 4);
    }
    else
    {
      const uint32_t bits = ((exponent + 112u) << 23) | (mantissa << 13);
      std::memcpy(&f, &bits, 4);
    }
    uint32_t out;
    std::memcpy(&out, &f, 4);
    out |= sign;
    std::memcpy(&f, &out, 4);
    return f;
  }
};

struct half2
{
  half x, y;
  half2() = default;
  half2(float a_x, float a_y) : x(a_x), y(a_y) {}
  explicit half2(float a) : x(a), y(a) {}
  explicit half2(const float2& v) : x(v.x), y(v.y) {}
};

struct half4
{
  half x, y, z, w;
  half4() = default;
  half4(float a_x, float a_y, float a_z, float a_w) : x(a_x), y(a_y), z(a_z), w(a_w) {}
  explicit half4(float a) : x(a), y(a), z(a), w(a) {}
  explicit half4(const float a[4]) : x(a[0]), y(a[1]), z(a[2]), w(a[3]) {}
  explicit half4(const float4& v) : x(v.x), y(v.y), z(v.z), w(v.w) {}
};
static_assert(sizeof(half2) == 4 && sizeof(half4) == 8, "half layouts");

inline float4::float4(const half4& v) : x(v.x), y(v.y), z(v.z), w(v.w) {}
inline float4 to_float4(const half4& v) { return float4(v); }
inline float2 to_float2(const half2& v) { return float2(v.x, v.y); }

// ---------------------------------------------------------------- complex numbers (float)
struct complex
{
  float re = 0.0f, im = 0.0f;
  complex() = default;
  complex(float a_re) : re(a_re), im(0.0f) {}  // implicit, as a real number is a complex one
  complex(float a_re, float a_im) : re(a_re), im(a_im) {}

  complex operator-() const { return complex(-re, -im); }
  complex operator+(const complex& b) const { return complex(re + b.re, im + b.im); }
  complex operator-(const complex& b) const { return complex(re - b.re, im - b.im); }
  complex operator*(const complex& b) const { return complex(re * b.re - im * b.im, re * b.im + im * b.re); }
  complex operator/(const complex& b) const
  {
    const float d = b.re * b.re + b.im * b.im;
    return complex((re * b.re + im * b.im) / d, (im * b.re - re * b.im) / d);
  }
};
inline complex operator+(float a, const complex& b) { return complex(a) + b; }
inline complex operator-(float a, const complex& b) { return complex(a) - b; }
inline complex operator*(float a, const complex& b) { return complex(a * b.re, a * b.im); }
inline complex operator/(float a, const complex& b) { return complex(a) / b; }
inline float real(const complex& c) { return c.re; }
inline float imag(const complex& c) { return c.im; }
inline float complex_norm(const complex& c) { return c.re * c.re + c.im * c.im; }  // |c|^2
inline float complex_abs(const complex& c) { return std::sqrt(complex_norm(c)); }
// The principal square root (pbrt's algorithm); 0 at 0.
inline complex complex_sqrt(const complex& z)
{
  const float n = complex_abs(z), t1 = std::sqrt(0.5f * (n + std::abs(z.re))), t2 = 0.5f * z.im / t1;
  if (n == 0.0f)
    return complex(0.0f);
  if (z.re >= 0.0f)
    return complex(t1, t2);
  return complex(std::abs(t2), std::copysign(t1, z.im));
}

// ---------------------------------------------------------------- atomics and reductions into arrays
// InterlockedAdd(mem, v) adds atomically, from any number of threads (the GPU's atomicAdd); the
// three-argument form also gives the value before the add. These are atomic whether or not the
// code is compiled with OpenMP.
inline void InterlockedAdd(int& mem, int data) { __atomic_fetch_add(&mem, data, __ATOMIC_RELAXED); }
inline void InterlockedAdd(uint& mem, uint data) { __atomic_fetch_add(&mem, data, __ATOMIC_RELAXED); }
inline void InterlockedAdd(int& mem, int data, int& a_res) { a_res = __atomic_fetch_add(&mem, data, __ATOMIC_RELAXED); }
inline void InterlockedAdd(uint& mem, uint data, uint& a_res) { a_res = __atomic_fetch_add(&mem, data, __ATOMIC_RELAXED); }
inline void InterlockedAdd(float& mem, float data, float& a_res)
{
  float expected, desired;
  __atomic_load(&mem, &expected, __ATOMIC_RELAXED);
  do
    desired = expected + data;  // a failed exchange updates `expected` to what is there now
  while (!__atomic_compare_exchange(&mem, &expected, &desired, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED));
  a_res = expected;
}
inline void InterlockedAdd(float& mem, float data)
{
  float before;
  InterlockedAdd(mem, data, before);
}

// The older names: atomicAdd(mem, v) is InterlockedAdd and gives the value before the add, as
// GLSL's atomicAdd does; InterlockedAdd3f adds a float3 to three consecutive floats of an array.
inline int atomicAdd(int& mem, int data) { int before; InterlockedAdd(mem, data, before); return before; }
inline uint atomicAdd(uint& mem, uint data) { uint before; InterlockedAdd(mem, data, before); return before; }
inline float atomicAdd(float& mem, float data) { float before; InterlockedAdd(mem, data, before); return before; }
inline void InterlockedAdd3f(float* arr, int offset, float3 val)
{
  InterlockedAdd(arr[offset + 0], val.x);
  InterlockedAdd(arr[offset + 1], val.y);
  InterlockedAdd(arr[offset + 2], val.z);
}

// Sums from many threads into the elements of a std::vector (kernel_slicer's 045_reduce_add):
//   ReduceAddInit(v, n);  kernel1D_X(...) { ... ReduceAdd(v, index, value); ... }  ReduceAddComplete(v);
// Init sizes and zeroes the vector, ReduceAdd adds a finite value to an element atomically, and
// Complete finishes (nothing is left to do: each add went to the element itself). The order of
// the adds varies, so float sums may differ in their last bits from run to run.
template <typename IndexType> inline IndexType align(IndexType a_size, IndexType a_alignment)
{
  return (a_size + a_alignment - 1) / a_alignment * a_alignment;
}
template <typename T> inline size_t ReduceAddInit(std::vector<T>& a_vec, size_t a_targetSize)
{
  a_vec.assign(a_targetSize, T(0));
  return align(a_targetSize, size_t(16));
}
template <typename T> inline void ReduceAddComplete(std::vector<T>& a_vec) { (void)a_vec; }
template <typename T, typename IndexType> inline void ReduceAdd(std::vector<T>& a_vec, IndexType offset, T val)
{
  if (std::isfinite(float(val)))
    InterlockedAdd(a_vec[size_t(offset)], val);
}
template <typename T, typename IndexType> inline void ReduceAdd(std::vector<T>& a_vec, IndexType offset, IndexType a_sizeAligned, T val)
{
  (void)a_sizeAligned;
  ReduceAdd(a_vec, offset, val);
}

#undef LM_VEC2_BINOP
#undef LM_VEC3_BINOP
#undef LM_VEC4_BINOP
#undef LM_VEC_ARITH
#undef LM_UNARY2
#undef LM_UNARY3
#undef LM_UNARY4
#undef LM_BINARY2
#undef LM_BINARY3
#undef LM_BINARY4
#undef LM_MINMAX
#undef LM_FLOAT_FUNCS
#undef LITEMATH_YIELDS_TO_USER

} // namespace LiteMath
