// Tests for LiteMath. Expected values are computed by hand or by independent formulas
// (double precision Gauss-Jordan, explicit trigonometry), not by the functions under test.
#include <catch2/catch.hpp>

#include "Gang.h"
#include "LiteMath.h"

#include <cstddef>
#include <cstring>
#include <limits>
#include <utility>
#include <random>
#include <type_traits>

using namespace LiteMath;

namespace
{
bool approxEq(float a, float b, float eps = 1e-5f) { return std::abs(a - b) <= eps * (1.0f + std::abs(b)); }
bool approxEq(const float3& a, const float3& b, float eps = 1e-5f)
{
  return approxEq(a.x, b.x, eps) && approxEq(a.y, b.y, eps) && approxEq(a.z, b.z, eps);
}
bool approxEq(const float4& a, const float4& b, float eps = 1e-5f)
{
  return approxEq(a.x, b.x, eps) && approxEq(a.y, b.y, eps) && approxEq(a.z, b.z, eps) && approxEq(a.w, b.w, eps);
}
bool isIdentity(const float4x4& m, float eps)
{
  for (int r = 0; r < 4; r++)
    for (int c = 0; c < 4; c++)
      if (std::abs(m(r, c) - (r == c ? 1.0f : 0.0f)) > eps)
        return false;
  return true;
}

// Reference inverse by Gauss-Jordan elimination with partial pivoting, in double precision.
bool gaussJordanInverse(const double in[4][4], double out[4][4])
{
  double a[4][8];
  for (int r = 0; r < 4; r++)
    for (int c = 0; c < 8; c++)
      a[r][c] = c < 4 ? in[r][c] : (c - 4 == r ? 1.0 : 0.0);
  for (int col = 0; col < 4; col++)
  {
    int piv = col;
    for (int r = col + 1; r < 4; r++)
      if (std::abs(a[r][col]) > std::abs(a[piv][col]))
        piv = r;
    if (std::abs(a[piv][col]) < 1e-12)
      return false;
    for (int c = 0; c < 8; c++)
      std::swap(a[col][c], a[piv][c]);
    const double d = a[col][col];
    for (int c = 0; c < 8; c++)
      a[col][c] /= d;
    for (int r = 0; r < 4; r++)
      if (r != col)
      {
        const double f = a[r][col];
        for (int c = 0; c < 8; c++)
          a[r][c] -= f * a[col][c];
      }
  }
  for (int r = 0; r < 4; r++)
    for (int c = 0; c < 4; c++)
      out[r][c] = a[r][c + 4];
  return true;
}
} // namespace

TEST_CASE("LiteMath vector layout", "[litemath]")
{
  static_assert(sizeof(float2) == 8 && alignof(float2) == 8, "");
  static_assert(sizeof(float3) == 12 && alignof(float3) == 4, "");
  static_assert(sizeof(float4) == 16 && alignof(float4) == 16, "");
  static_assert(sizeof(int3) == 12 && sizeof(uint4) == 16 && alignof(int4) == 16, "");
  static_assert(sizeof(float4x4) == 64 && alignof(float4x4) == 16, "");
  static_assert(sizeof(float3x3) == 36, "");
  static_assert(std::is_same<uint, uint32_t>::value, "");
  static_assert(offsetof(float4, w) == 12 && offsetof(float3, z) == 8, "");
  static_assert(std::is_standard_layout<float4x4>::value, "");

  // Matrices are column-major in memory: element (row 1, col 2) lives at float index 2*4+1.
  const float4x4 m(1, 2, 3, 4,     //
                   5, 6, 7, 8,     //
                   9, 10, 11, 12,  //
                   13, 14, 15, 16);
  const float* raw = &m.m_col[0].x;
  CHECK(raw[2 * 4 + 1] == 7.0f);
  CHECK(raw[3] == 13.0f);
  CHECK(raw[12] == 4.0f);
}

TEST_CASE("LiteMath vector constructors and indexing", "[litemath]")
{
  float4 z;
  CHECK((z.x == 0 && z.y == 0 && z.z == 0 && z.w == 0));
  int3 zi;
  CHECK((zi.x == 0 && zi.y == 0 && zi.z == 0));
  const float3 s(1.0f);
  CHECK((s.x == 1 && s.y == 1 && s.z == 1));
  float4 v(1, 2, 3, 4);
  CHECK(v[2] == 3.0f);
  v[3] = 7.0f;
  CHECK(v.w == 7.0f);
  const float4 f4(float3(1, 2, 3), 9.0f);
  CHECK((f4.z == 3.0f && f4.w == 9.0f));
  const float3 f3(float2(5, 6), 7.0f);
  CHECK((f3.x == 5.0f && f3.z == 7.0f));
  const uint2 u = make_uint2(3u, 4u);
  CHECK(u[1] == 4u);
  CHECK(make_float3(1, 2, 3).y == 2.0f);
  CHECK(make_int4(1, 2, 3, 4).w == 4);
}

TEST_CASE("LiteMath arithmetic operators", "[litemath]")
{
  const float3 a(1, 2, 3), b(4, 5, 6);
  CHECK(approxEq(a + b, float3(5, 7, 9)));
  CHECK(approxEq(b - a, float3(3, 3, 3)));
  CHECK(approxEq(a * b, float3(4, 10, 18)));
  CHECK(approxEq(b / a, float3(4, 2.5f, 2)));
  CHECK(approxEq(a * 2.0f, float3(2, 4, 6)));
  CHECK(approxEq(2.0f * a, float3(2, 4, 6)));
  CHECK(approxEq(6.0f / a, float3(6, 3, 2)));
  CHECK(approxEq(a - 1.0f, float3(0, 1, 2)));
  CHECK(approxEq(-a, float3(-1, -2, -3)));
  float4 c(1, 1, 1, 1);
  c += float4(1, 2, 3, 4);
  c *= 2.0f;
  c -= float4(1.0f);
  c /= float4(1, 5, 7, 9);
  CHECK(approxEq(c, float4(3, 1, 1, 1)));

  int2 i(7, -9);
  i = i / 2;
  CHECK((i.x == 3 && i.y == -4));
  const uint4 u = uint4(10u, 20u, 30u, 40u) - uint4(1u) * 2u;
  CHECK((u.x == 8u && u.w == 38u));
  const int3 ineg = -int3(1, -2, 3);
  CHECK((ineg.x == -1 && ineg.y == 2 && ineg.z == -3));
}

TEST_CASE("LiteMath min/max coexist with std", "[litemath]")
{
  CHECK(LiteMath::min(1.0f, 2.0f) == 1.0f);
  CHECK(LiteMath::max(1.0f, 2.0f) == 2.0f);
  CHECK(std::min(3, 2) == 2);
  CHECK(min(1.5f, -2.0f) == -2.0f);
  const float3 a(1, 5, 3), b(2, 4, 3);
  CHECK(approxEq(min(a, b), float3(1, 4, 3)));
  CHECK(approxEq(max(a, b), float3(2, 5, 3)));
  const int3 mi = max(int3(1, -5, 3), int3(0, 0, 0));
  CHECK((mi.x == 1 && mi.y == 0 && mi.z == 3));
  CHECK(clamp(5.0f, 0.0f, 1.0f) == 1.0f);
  CHECK(clamp(-3, 0, 10) == 0);
  CHECK(approxEq(clamp(float3(-1, 0.5f, 2), 0.0f, 1.0f), float3(0, 0.5f, 1)));
  CHECK(approxEq(abs(float3(-1, 2, -3)), float3(1, 2, 3)));
  CHECK(abs(int2(-4, 4)).x == 4);
  CHECK(abs(-2.5f) == 2.5f);
  CHECK(sqrt(16.0f) == 4.0f);
}

// float4 runs on SSE in compiled C++ (LITEMATH_FLOAT4_SSE): each lane must give the same bits as the
// scalar std::min/std::max and operators, including the operand order that decides NaN and +-0.
TEST_CASE("LiteMath float4 arithmetic, min/max and lane_mask_le match the scalar definitions bit for bit", "[litemath]")
{
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const float4 a(nan, 0.0f, -0.0f, 1.5f), b(1.0f, -0.0f, 0.0f, nan);
  const float4 c(-inf, 3.0f, 1e-40f, -2.0f), d(inf, -7.25f, 3.0f, 0.0f);
  auto bits = [](float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
  };
  for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, a}, std::pair{c, d}, std::pair{d, c}})
  {
    const float4 lo = min(x, y), hi = max(x, y), sum = x + y, diff = x - y, prod = x * y, quot = x / y, scaled = x * 3.0f;
    for (int i = 0; i < 4; ++i)
    {
      INFO("lane " << i << ": " << x[i] << ", " << y[i]);
      CHECK(bits(lo[i]) == bits(std::min(x[i], y[i])));
      CHECK(bits(hi[i]) == bits(std::max(x[i], y[i])));
      CHECK(bits(sum[i]) == bits(x[i] + y[i]));
      CHECK(bits(diff[i]) == bits(x[i] - y[i]));
      CHECK(bits(prod[i]) == bits(x[i] * y[i]));
      CHECK(bits(quot[i]) == bits(x[i] / y[i]));
      CHECK(bits(scaled[i]) == bits(x[i] * 3.0f));
    }
    // lane_mask_le: bit i is x[i] <= y[i] as C++ compares floats (NaN false, -0 == +0).
    uint32_t expected = 0;
    for (int i = 0; i < 4; ++i) expected |= (x[i] <= y[i] ? 1u : 0u) << i;
    CHECK(lane_mask_le(x, y) == expected);
  }
  CHECK(lane_mask_le(float4(1, 2, 3, 4), float4(1, 2, 3, 4)) == 15u);
  CHECK(lane_mask_le(float4(1, 5, 3, 7), float4(2, 4, 3, 6)) == 5u);  // lanes 0 and 2
}

TEST_CASE("LiteMath scalar and componentwise functions", "[litemath]")
{
  CHECK(approxEq(fract(-1.25f), 0.75f));
  CHECK(approxEq(fract(2.75f), 0.75f));
  CHECK(sign(-3.0f) == -1.0f);
  CHECK(sign(0.0f) == 0.0f);
  CHECK(sign(2.0f) == 1.0f);
  CHECK(approxEq(sign(float3(-2, 0, 5)), float3(-1, 0, 1)));
  CHECK(approxEq(lerp(2.0f, 4.0f, 0.25f), 2.5f));
  CHECK(approxEq(mix(float3(0), float3(10, 20, 30), 0.5f), float3(5, 10, 15)));
  CHECK(step(0.5f, 0.4f) == 0.0f);
  CHECK(step(0.5f, 0.5f) == 1.0f);
  CHECK(smoothstep(0.0f, 1.0f, 0.5f) == Approx(0.5f));
  CHECK(smoothstep(0.0f, 2.0f, 0.5f) == Approx(0.15625f)); // t=0.25: 3t^2-2t^3
  CHECK(smoothstep(0.0f, 1.0f, -1.0f) == 0.0f);
  CHECK(inversesqrt(4.0f) == Approx(0.5f));
  CHECK(approxEq(floor(float3(1.5f, -1.5f, 2.0f)), float3(1, -2, 2)));
  CHECK(approxEq(ceil(float3(1.5f, -1.5f, 2.0f)), float3(2, -1, 2)));
  CHECK(approxEq(fract(float2(1.25f, -0.25f)).y, 0.75f));
  CHECK(approxEq(pow(float3(2, 3, 4), float3(3, 2, 0.5f)), float3(8, 9, 2)));
  CHECK(approxEq(sin(float3(0, M_PI_F / 2, M_PI_F)).y, 1.0f));
  CHECK(approxEq(cos(float4(0.0f)), float4(1.0f)));
  CHECK(approxEq(log(exp(float3(1, 2, 3))), float3(1, 2, 3)));
  CHECK(approxEq(sqrt(float4(4, 9, 16, 25)), float4(2, 3, 4, 5)));
  CHECK(approxEq(inversesqrt(float2(4, 16)).y, 0.25f));
  CHECK(hmin(float4(3, -1, 2, 5)) == -1.0f);
  CHECK(hmax(float3(3, -1, 7)) == 7.0f);
  CHECK(hmin(float3(3, -1, 7)) == -1.0f);
}

TEST_CASE("LiteMath geometry functions", "[litemath]")
{
  CHECK(dot(float3(1, 2, 3), float3(4, -5, 6)) == 12.0f);
  CHECK(approxEq(cross(float3(1, 0, 0), float3(0, 1, 0)), float3(0, 0, 1)));
  CHECK(approxEq(cross(float3(0, 1, 0), float3(1, 0, 0)), float3(0, 0, -1)));
  CHECK(length(float3(3, 4, 12)) == Approx(13.0f));
  CHECK(distance(float2(1, 1), float2(4, 5)) == Approx(5.0f));
  CHECK(approxEq(normalize(float3(0, 3, 4)), float3(0, 0.6f, 0.8f)));
  CHECK(length(normalize(float4(1, 2, 3, 4))) == Approx(1.0f));

  // reflect: mirror about the plane with normal +Y.
  CHECK(approxEq(reflect(float3(1, -1, 0), float3(0, 1, 0)), float3(1, 1, 0)));

  // refract with eta = 1 keeps the direction.
  const float3 I = normalize(float3(1, -2, 0));
  CHECK(approxEq(refract(I, float3(0, 1, 0), 1.0f), I));

  // Snell's law: sin(theta_t) = eta * sin(theta_i), computed with explicit trigonometry.
  const float  thetaI = 30.0f * DEG_TO_RAD, eta = 1.0f / 1.5f;
  const float3 In(std::sin(thetaI), -std::cos(thetaI), 0.0f);
  const float3 T      = refract(In, float3(0, 1, 0), eta);
  const float  sinT   = eta * std::sin(thetaI);
  CHECK(approxEq(T, float3(sinT, -std::sqrt(1.0f - sinT * sinT), 0.0f)));

  // Total internal reflection (glass -> air at 60 degrees) returns the zero vector.
  const float  theta2 = 60.0f * DEG_TO_RAD;
  const float3 tir    = refract(float3(std::sin(theta2), -std::cos(theta2), 0.0f), float3(0, 1, 0), 1.5f);
  CHECK((tir.x == 0.0f && tir.y == 0.0f && tir.z == 0.0f));
}

TEST_CASE("LiteMath conversions and bit casts", "[litemath]")
{
  const float4 v(1, 2, 3, 4);
  CHECK(approxEq(to_float3(v), float3(1, 2, 3)));
  CHECK(to_float4(float3(1, 2, 3), 5.0f).w == 5.0f);
  CHECK(to_float2(v).y == 2.0f);
  CHECK(to_float2(float3(7, 8, 9)).x == 7.0f);
  const int3 i = to_int3(float3(1.7f, -1.7f, 2.0f)); // truncation toward zero, like GLSL int()
  CHECK((i.x == 1 && i.y == -1 && i.z == 2));
  CHECK(to_uint2(float2(3.9f, 0.2f)).x == 3u);
  CHECK(approxEq(to_float3(int3(-1, 2, 3)), float3(-1, 2, 3)));
  CHECK(to_float4(uint4(1u, 2u, 3u, 4000000000u)).w == 4.0e9f);
  CHECK(to_int4(float4(-0.5f)).x == 0);

  CHECK(as_uint(1.0f) == 0x3F800000u);
  CHECK(as_int(-2.0f) == int(0xC0000000u));
  CHECK(as_float(0x40490FDBu) == Approx(3.14159265f));
  for (float x : {0.0f, -0.0f, 1.5f, -123.456f, 1e-30f, INF_POSITIVE})
  {
    CHECK(as_float(as_int(x)) == x);
    CHECK(as_float(as_uint(x)) == x);
  }
  const uint4 bits = as_uint(float4(1.0f, -1.0f, 0.0f, 2.0f));
  CHECK((bits.x == 0x3F800000u && bits.y == 0xBF800000u && bits.z == 0u && bits.w == 0x40000000u));
  CHECK(approxEq(as_float(as_int(float4(1, -2, 3, -4))), float4(1, -2, 3, -4)));
}

TEST_CASE("LiteMath matrix construction and access", "[litemath]")
{
  const float4x4 id;
  CHECK(isIdentity(id, 0.0f));
  const float3x3 id3;
  CHECK((id3(0, 0) == 1 && id3(0, 1) == 0 && id3(2, 2) == 1));

  // Constructor takes row-major reading order; operator[] returns columns.
  const float4x4 m(1, 2, 3, 4,    //
                   5, 6, 7, 8,    //
                   9, 10, 11, 12, //
                   13, 14, 15, 16);
  CHECK(m(0, 3) == 4.0f);
  CHECK(m(3, 0) == 13.0f);
  CHECK(approxEq(m[1], float4(2, 6, 10, 14)));
  CHECK(approxEq(m.get_col(3), float4(4, 8, 12, 16)));
  CHECK(approxEq(m.get_row(2), float4(9, 10, 11, 12)));

  float4x4 w;
  w.set_row(1, float4(1, 2, 3, 4));
  CHECK(w(1, 2) == 3.0f);
  CHECK(w[2].y == 3.0f);
  w.set_col(0, float4(9, 8, 7, 6));
  CHECK(w(3, 0) == 6.0f);
  w(2, 3) = 42.0f;
  CHECK(w[3].z == 42.0f);

  // Matrix * vector equals row-by-row dot products.
  const float4 v(1, -1, 2, 0.5f);
  const float4 r = m * v;
  for (int row = 0; row < 4; row++)
    CHECK(r[row] == Approx(dot(m.get_row(row), v)));

  // Matrix * matrix: element (i,j) is row i of A dotted with column j of B.
  const float4x4 b(2, 0, 1, 0, //
                   0, 1, 0, 3, //
                   1, 1, 1, 1, //
                   0, 2, 0, 1);
  const float4x4 ab = m * b;
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++)
      CHECK(ab(i, j) == Approx(dot(m.get_row(i), b.get_col(j))));

  const float4x4 t = transpose(m);
  CHECK(t(0, 3) == 13.0f);
  CHECK(t(3, 0) == 4.0f);
  CHECK((m * 2.0f)(1, 1) == 12.0f);
  CHECK((0.5f * m)(3, 3) == 8.0f);

  const float3x3 m3(1, 2, 3, //
                    4, 5, 6, //
                    7, 8, 10);
  CHECK(m3(1, 2) == 6.0f);
  CHECK(approxEq(m3[0], float3(1, 4, 7)));
  const float3 r3 = m3 * float3(1, 0, -1);
  CHECK(approxEq(r3, float3(-2, -2, -3)));
  CHECK(transpose(m3)(2, 0) == 3.0f);
  // det = 1*(50-48) - 2*(40-42) + 3*(32-35) = 2 + 4 - 9 = -3
  CHECK(determinant(m3) == Approx(-3.0f));
}

TEST_CASE("LiteMath inverse of random matrices", "[litemath]")
{
  std::mt19937                          rng(12345);
  std::uniform_real_distribution<float> dist(-2.0f, 2.0f);
  for (int iter = 0; iter < 50; iter++)
  {
    float4x4 m;
    double   md[4][4];
    for (int r = 0; r < 4; r++)
      for (int c = 0; c < 4; c++)
        md[r][c] = m(r, c) = dist(rng) + (r == c ? 3.0f : 0.0f); // diagonal bias keeps it well conditioned
    double ref[4][4];
    REQUIRE(gaussJordanInverse(md, ref));

    const float4x4 inv = inverse4x4(m);
    CHECK(isIdentity(inv * m, 1e-4f));
    CHECK(isIdentity(m * inverse(m), 1e-4f));
    for (int r = 0; r < 4; r++)
      for (int c = 0; c < 4; c++)
        CHECK(inv(r, c) == Approx(ref[r][c]).margin(1e-4));

    // det(M) * det(M^-1) == 1 and it matches the product of Gauss-Jordan pivots indirectly.
    CHECK(determinant(m) * determinant(inv) == Approx(1.0f).epsilon(1e-3));

    float3x3 m3;
    for (int r = 0; r < 3; r++)
      for (int c = 0; c < 3; c++)
        m3(r, c) = m(r, c);
    const float3x3 p = inverse(m3) * m3;
    for (int r = 0; r < 3; r++)
      for (int c = 0; c < 3; c++)
        CHECK(p(r, c) == Approx(r == c ? 1.0f : 0.0f).margin(1e-4));
  }
}

TEST_CASE("LiteMath transforms", "[litemath]")
{
  const float4x4 t = translate4x4(float3(1, 2, 3));
  CHECK(approxEq(t[3], float4(1, 2, 3, 1))); // translation lives in column 3
  CHECK(approxEq(t.get_row(0), float4(1, 0, 0, 1)));
  CHECK(approxEq(mul4x3(t, float3(1, 1, 1)), float3(2, 3, 4)));
  CHECK(approxEq(mul3x3(t, float3(1, 1, 1)), float3(1, 1, 1))); // directions ignore translation

  const float4x4 s = scale4x4(float3(2, 3, 4));
  CHECK(approxEq(mul4x3(s, float3(1, 1, 1)), float3(2, 3, 4)));
  CHECK(approxEq(mul4x3(t * s, float3(1, 1, 1)), float3(3, 5, 7))); // scale first, then translate

  const float a = 0.5f * M_PI_F;
  CHECK(approxEq(mul3x3(rotate4x4Z(a), float3(1, 0, 0)), float3(0, 1, 0)));
  CHECK(approxEq(mul3x3(rotate4x4X(a), float3(0, 1, 0)), float3(0, 0, 1)));
  CHECK(approxEq(mul3x3(rotate4x4Y(a), float3(0, 0, 1)), float3(1, 0, 0)));

  // Arbitrary axis rotation agrees with the axis-aligned versions and keeps the axis fixed.
  const float ang = 0.7f;
  const float4x4 rz = rotate4x4(float3(0, 0, 2), ang), rzRef = rotate4x4Z(ang);
  const float4x4 rx = rotate4x4(float3(1, 0, 0), ang), rxRef = rotate4x4X(ang);
  const float4x4 ry = rotate4x4(float3(0, 1, 0), ang), ryRef = rotate4x4Y(ang);
  for (int c = 0; c < 4; c++)
  {
    CHECK(approxEq(rz[c], rzRef[c]));
    CHECK(approxEq(rx[c], rxRef[c]));
    CHECK(approxEq(ry[c], ryRef[c]));
  }
  const float3 axis = normalize(float3(1, 2, 3));
  CHECK(approxEq(mul3x3(rotate4x4(axis, 1.3f), axis), axis));
  // Rotating a vector perpendicular to the axis by angle a: cos(a) between input and output.
  const float3 perp = normalize(cross(axis, float3(0, 0, 1)));
  CHECK(dot(mul3x3(rotate4x4(axis, 1.3f), perp), perp) == Approx(std::cos(1.3f)));
}

TEST_CASE("LiteMath lookAt and perspective follow OpenGL conventions", "[litemath]")
{
  const float3   eye(1, 2, 3), center(4, 6, 3), up(0, 0, 1);
  const float4x4 view = lookAt(eye, center, up);
  CHECK(approxEq(mul4x3(view, eye), float3(0, 0, 0), 1e-5f));
  // center is at distance 5 straight ahead: -Z in view space.
  const float3 c = mul4x3(view, center);
  CHECK(c.x == Approx(0.0f).margin(1e-5));
  CHECK(c.y == Approx(0.0f).margin(1e-5));
  CHECK(c.z == Approx(-5.0f));
  // The up vector maps to +Y (it is perpendicular to the view direction here).
  CHECK(approxEq(mul3x3(view, up), float3(0, 1, 0)));
  // Right-handed: camera right = forward x up = (0.6,0.8,0) x (0,0,1) = (0.8,-0.6,0) maps to +X.
  CHECK(approxEq(mul3x3(view, float3(0.8f, -0.6f, 0.0f)), float3(1, 0, 0)));

  const float    n = 0.5f, f = 100.0f, fovy = 60.0f, aspect = 2.0f;
  const float4x4 proj = perspectiveMatrix(fovy, aspect, n, f);
  auto           ndc  = [&](const float3& p) {
    const float4 h = proj * float4(p, 1.0f);
    return float3(h.x / h.w, h.y / h.w, h.z / h.w);
  };
  CHECK(ndc(float3(0, 0, -n)).z == Approx(-1.0f));
  CHECK(ndc(float3(0, 0, -f)).z == Approx(1.0f));
  CHECK(ndc(float3(0.1f, 0.2f, -n)).z == Approx(-1.0f));
  // Top edge of the frustum at distance d: y = d * tan(fovy/2) -> ndc y = 1; right edge x = aspect * that.
  const float d = 10.0f, halfH = d * std::tan(0.5f * fovy * M_PI_F / 180.0f);
  CHECK(ndc(float3(0, halfH, -d)).y == Approx(1.0f));
  CHECK(ndc(float3(aspect * halfH, 0, -d)).x == Approx(1.0f));
  CHECK((proj * float4(0, 0, -d, 1)).w == Approx(d)); // w = -z_view
}

TEST_CASE("LiteMath Box4f", "[litemath]")
{
  Box4f b;
  CHECK(b.empty());
  CHECK(b.surfaceArea() == 0.0f);
  CHECK(b.boxMin.x == INF_POSITIVE);
  CHECK(b.boxMax.y == INF_NEGATIVE);
  b.include(float4(1, 2, 3, 0));
  CHECK_FALSE(b.empty());
  b.include(float4(2, 4, 6, 0));
  CHECK(approxEq(b.center(), float4(1.5f, 3.0f, 4.5f, 0.0f)));
  CHECK(approxEq(b.extent(), float4(1, 2, 3, 0)));
  CHECK(b.surfaceArea() == Approx(22.0f)); // 2*(1*2 + 2*3 + 3*1)
  CHECK(b.axisOfMaxExtent() == 2);

  Box4f other;
  other.include(float4(-10, 0, 0, 0));
  b.include(other);
  CHECK(b.boxMin.x == -10.0f);
  CHECK(b.axisOfMaxExtent() == 0);
  CHECK(INF_NEGATIVE < -1e38f);
  CHECK(EPSILON == 1e-6f);
  CHECK(DEG_TO_RAD * 180.0f == Approx(M_PI_F));
}

TEST_CASE("Gang.h in a gang of one: a lane's share of a loop is the whole loop", "[litemath][gang]")
{
  // The original class and the CPU and Vulkan backends run a gang of one; ISPC prints these as
  // programIndex, packmask, extract and a load of the components across the lanes.
  CHECK(crossrt::GangSize() == 1);
  CHECK(crossrt::LaneIndex() == 0);
  CHECK(crossrt::LaneBits(true) == 1u);
  CHECK(crossrt::LaneBits(false) == 0u);
  CHECK(crossrt::LaneValue(7, 0) == 7);
  CHECK(crossrt::LaneValue(2.5f, 0) == 2.5f);
  const LiteMath::float4 v(1.0f, 2.0f, 3.0f, 4.0f);
  float sum = 0.0f;
  for (int first = 0; first < 4; first += crossrt::GangSize())
    sum += crossrt::LaneOf(v, first);
  CHECK(sum == 10.0f);
  CHECK(crossrt::LaneOf(v, 2) == 3.0f);
  CHECK(crossrt::LaneOf(v, 6) == 4.0f);  // past the last component: the last
  CHECK(crossrt::LaneOf(LiteMath::uint4(5u, 6u, 7u, 8u), 1) == 6u);
  // A gang of one is a quad's first lane, and reads its own lane.
  CHECK(crossrt::LaneOfQuad(v) == 1.0f);
  CHECK(crossrt::LaneOfQuad(LiteMath::int4(-3, 6, 7, 8)) == -3);
  CHECK(crossrt::FromLane(2.5f, 0) == 2.5f);
  CHECK(crossrt::FromLane(true, 0));
}
