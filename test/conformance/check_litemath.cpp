// Cases about the paper's LiteMath API in kernels: matrices, conversions and constants, half4,
// complex, InterlockedAdd, the ReduceAdd family, a user's own function named like a LiteMath one,
// fields of arrays of structs, and the integer arithmetic the ISPC classes compute their own way
// (bit scans and counts, division and remainder).
#include "Conformance.h"

#include "LiteMath.h"
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

// A case compiles where this build translated its class (CONFORMANCE_CLASSES); main checks that all were.
#if __has_include("IntDivision_CPU.h")
#include "IntDivision_CPU.h"
#include "IntDivision_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "IntDivision_ISPC.h"
#endif
#endif
#if __has_include("BitScans_CPU.h")
#include "BitScans_CPU.h"
#include "BitScans_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "BitScans_ISPC.h"
#endif
#endif
#if __has_include("BoxFields_CPU.h")
#include "BoxFields_CPU.h"
#include "BoxFields_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "BoxFields_ISPC.h"
#endif
#endif
#if __has_include("Transforms_CPU.h")
#include "Transforms_CPU.h"
#include "Transforms_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Transforms_ISPC.h"
#endif
#endif
#if __has_include("Conversions_CPU.h")
#include "Conversions_CPU.h"
#include "Conversions_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Conversions_ISPC.h"
#endif
#endif
#if __has_include("HalfPack_CPU.h")
#include "HalfPack_CPU.h"
#include "HalfPack_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "HalfPack_ISPC.h"
#endif
#endif
#if __has_include("ThinFilm_CPU.h")
#include "ThinFilm_CPU.h"
#include "ThinFilm_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "ThinFilm_ISPC.h"
#endif
#endif
#if __has_include("Histogram_CPU.h")
#include "Histogram_CPU.h"
#include "Histogram_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Histogram_ISPC.h"
#endif
#endif
#if __has_include("OldAtomics_CPU.h")
#include "OldAtomics_CPU.h"
#include "OldAtomics_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "OldAtomics_ISPC.h"
#endif
#endif
#if __has_include("AccumGrid_CPU.h")
#include "AccumGrid_CPU.h"
#include "AccumGrid_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "AccumGrid_ISPC.h"
#endif
#endif
#if __has_include("Projector_CPU.h")
#include "Projector_CPU.h"
#include "Projector_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "Projector_ISPC.h"
#endif
#endif
#if __has_include("VectorFuncs_CPU.h")
#include "VectorFuncs_CPU.h"
#include "VectorFuncs_Vulkan.h"
#ifdef CONFORMANCE_ISPC
#include "VectorFuncs_ISPC.h"
#endif
#endif

using namespace conformance;
using LiteMath::float4;

namespace {

std::vector<float4> Points(int n) {
  std::vector<float4> v(n);
  for (int i = 0; i < n; i++) v[i] = float4(std::sin(0.1f * float(i)) * 3.0f, float(i % 11) - 5.0f, 0.05f * float(i), 1.0f + 0.01f * float(i));
  return v;
}

Outputs Flatten(const std::vector<float4>& v) {
  Outputs r;
  for (auto& p : v) Append(r, std::vector<float>{p.x, p.y, p.z, p.w});
  return r;
}

#if __has_include("Transforms_CPU.h")
Register transforms(MakeCase<Transforms>(
    "mul4x4x4, make_float4x4_from_rows/cols, rotate3x3X/Y/Z, float3x3 * float3", "transforms.h/.cpp", 1e-5, CONFORMANCE_MAKERS(Transforms),
    [](Transforms& t) {
      std::vector<float4> in = Points(200), out(200);
      t.Apply(200, in.data(), out.data());
      return Flatten(out);
    }));
#endif

#if __has_include("Conversions_CPU.h")
Register conversions(MakeCase<Conversions>(
    "to_int4(int3, w), int2(float2), to_float3, mod, cross3, M_TWOPI, INV_PI", "conversions.h/.cpp", 1e-5, CONFORMANCE_MAKERS(Conversions),
    [](Conversions& c) {
      std::vector<float4> in = Points(150), out(150);
      std::vector<LiteMath::int4> ints(150);
      c.Run(150, in.data(), out.data(), ints.data());
      Outputs r = Flatten(out);
      for (auto& v : ints) r.insert(r.end(), {double(v.x), double(v.y), double(v.z), double(v.w)});
      return r;
    }));
#endif

#if __has_include("VectorFuncs_CPU.h")
Register vectorFuncs(MakeCase<VectorFuncs>(
    "floor, ceil, fract, sign, sqrt, inversesqrt, sin, cos, exp, log, pow, step, mod, lerp, mix, smoothstep of float2/3/4",
    "vector_funcs.h/.cpp", 1e-4, CONFORMANCE_MAKERS(VectorFuncs), [](VectorFuncs& f) {
      // Points(n)'s x is between -3 and 3, y whole numbers from -5 to 5 (floor and step on the edge), z from 0.
      std::vector<float4> in = Points(120), out(16 * 120);
      f.Apply(in.data(), out.data(), 120);
      return Flatten(out);
    }));
#endif

#if __has_include("HalfPack_CPU.h")
Register halfPack(MakeCase<HalfPack>(
    "half4: a member vector of 16-bit floats, packed and unpacked in kernels", "half_pack.h/.cpp", 1e-3, CONFORMANCE_MAKERS(HalfPack),
    [](HalfPack& h) {
      h.m_packed.resize(128);
      h.CommitDeviceData();
      std::vector<float4> in = Points(128), out(128);
      h.Pack(128, in.data());
      h.Unpack(128, out.data());
      return Flatten(out);
    }));
#endif

#if __has_include("ThinFilm_CPU.h")
Register thinFilm(MakeCase<ThinFilm>(
    "LiteMath::complex: constructors, + - * /, float * complex, complex_norm", "thin_film.h/.cpp", 1e-4, CONFORMANCE_MAKERS(ThinFilm),
    [](ThinFilm& f) {
      std::vector<float> cosTheta(256), out(256);
      for (int i = 0; i < 256; i++) cosTheta[i] = 0.05f + 0.95f * float(i) / 255.0f;
      f.Reflectance(256, cosTheta.data(), out.data());
      Outputs r;
      Append(r, out);
      return r;
    }));
#endif

#if __has_include("Histogram_CPU.h")
Register histogram(MakeCase<Histogram>(
    "InterlockedAdd on a member vector's and an output pointer's elements", "histogram.h/.cpp", 0.0, CONFORMANCE_MAKERS(Histogram),
    [](Histogram& h) {
      std::vector<float> values(4000);
      for (int i = 0; i < 4000; i++) values[i] = float((i * 7) % 1000) / 1000.0f;
      int sums[4] = {0, 0, 0, 0};
      h.CommitDeviceData();
      h.Count(4000, values.data(), sums);
      Outputs r;
      Append(r, h.m_bins);
      Append(r, std::vector<int>(sums, sums + 4));
      return r;
    }));
#endif

#if __has_include("AccumGrid_CPU.h")
Register accumGrid(MakeCase<AccumGrid>(
    "ReduceAddInit / ReduceAdd<float, uint32_t> / ReduceAddComplete", "accum_grid.h/.cpp", 1e-5, CONFORMANCE_MAKERS(AccumGrid),
    [](AccumGrid& a) {
      std::vector<float> values(3000);
      for (int i = 0; i < 3000; i++) values[i] = 0.25f * float(i % 9);
      a.CommitDeviceData();
      a.Accumulate(3000, values.data());
      Outputs r;
      Append(r, a.m_accum);
      return r;
    }));
#endif

#if __has_include("Projector_CPU.h")
Register projector(MakeCase<Projector>(
    "a user's own perspectiveMatrix beside using namespace LiteMath, float4x4::set_row in a kernel", "projector.h/.cpp", 1e-5, CONFORMANCE_MAKERS(Projector),
    [](Projector& p) {
      std::vector<float4> in = Points(100), out(100);
      for (auto& q : in) q.z -= 20.0f;
      p.Project(100, in.data(), out.data());
      return Flatten(out);
    }));
#endif

#if __has_include("IntDivision_CPU.h")
Register intDivision(MakeCase<IntDivision>(
    "integer / and % by a divisor per thread, by a member, by a constant; negative operands, unsigned above 2^31", "int_division.h/.cpp", 0.0,
    CONFORMANCE_MAKERS(IntDivision), [](IntDivision& d) {
      std::vector<int> a = {INT32_MIN, INT32_MIN, INT32_MAX, -7, 7, -7, 0, 123456789, -123456789, 1 << 30, INT32_MIN + 1, -1};
      std::vector<int> b = {2, 7, -3, 2, -2, -2, 5, 10, 10, 3, INT32_MAX, 4};
      std::vector<uint32_t> u = {0xFFFFFFFFu, 0x80000000u, 0x80000001u, 4000000000u, 0u, 1u, 7u, 0xFFFFFFFEu, 3000000000u, 12345u, 0x7FFFFFFFu, 99u};
      uint32_t h = 2024u;
      while (a.size() < 101)  // a count that leaves part of a gang
      {
        h = h * 1664525u + 1013904223u;
        a.push_back(int(h));
        h = h * 1664525u + 1013904223u;
        b.push_back(int(h) >> (h % 31u));  // from 0 (the kernel takes 1) to large, either sign
        h = h * 1664525u + 1013904223u;
        u.push_back(h);
        if (a.back() == INT32_MIN && b.back() == -1) b.back() = 1;  // undefined in C++
      }
      const int n = int(a.size());
      std::vector<int4> q(n, int4(-9));
      std::vector<uint4> uq(n, uint4(9u));
      d.SetStep(-5);
      d.CommitDeviceData();
      d.Divide(n, a.data(), b.data(), u.data(), q.data(), uq.data());
      // Known answers: INT_MIN / 2, INT_MIN % 7 (-2147483648 = 7 x -306783378 - 2), -7 / 2 and -7 % 2
      // (towards zero), 7 / -2, 0xFFFFFFFF / 2 and % 2, 0x80000000 / 7.
      if (q[0].x != -1073741824 || q[1].y != -2 || q[3].x != -3 || q[3].y != -1 || q[4].x != -3 || q[4].y != 1)
        throw std::runtime_error("the signed quotients and remainders should truncate towards zero");
      if (uq[0].x != 0x7FFFFFFFu || uq[0].y != 1u || uq[1].x != 306783378u)
        throw std::runtime_error("the unsigned quotients should be exact above 2^31");
      Outputs r;
      for (int i = 0; i < n; i++) Append(r, std::vector<double>{double(q[i].x), double(q[i].y), double(q[i].z), double(q[i].w),
                                                               double(uq[i].x), double(uq[i].y), double(uq[i].z), double(uq[i].w)});
      return r;
    }));
#endif

#if __has_include("BitScans_CPU.h")
Register bitScans(MakeCase<BitScans>(
    "__builtin_clz, __builtin_ctz and __builtin_popcount of 32-bit words, in a static helper and inline", "bit_scans.h/.cpp", 0.0,
    CONFORMANCE_MAKERS(BitScans), [](BitScans& b) {
      // The edges: zero, each bit alone, each run of low and of high bits, and words about 2^24 (where
      // a float holds a word exactly no more), then scrambled words; a count that leaves part of a gang.
      std::vector<uint32_t> words = {0u, 1u, 0x80000000u, 0x01000000u, 0x01FFFFFFu, 0xFFFFFFFFu, 0x00FFFFFFu, 0x00FFFFFEu, 0xFFFFFF80u};
      for (uint32_t k = 0; k < 32; k++)
      {
        words.push_back(1u << k);
        words.push_back((1u << k) - 1u);
        words.push_back(~((1u << k) - 1u));
      }
      uint32_t h = 12345u;
      while (words.size() < 200)
      {
        h = h * 1664525u + 1013904223u;
        words.push_back(h >> (h % 29u));
      }
      const int n = int(words.size()) - 3;  // 197
      std::vector<int4> counts(n, int4(-7));
      b.CommitDeviceData();
      b.Scan(n, words.data(), counts.data());
      // Known answers for the first words: 0, 1, 2^31, 2^24, 2^25 - 1, then 2^32 - 1 (leading, trailing, ones).
      const int known[6][3] = {{32, 32, 0}, {31, 0, 1}, {0, 31, 1}, {7, 24, 1}, {7, 0, 25}, {0, 0, 32}};
      for (int i = 0; i < 6; i++)
        if (counts[i].x != known[i][0] || counts[i].y != known[i][1] || counts[i].z != known[i][2])
          throw std::runtime_error("word " + std::to_string(i) + " should have its known counts");
      if (counts[3].w != 100 * 23 + 24)  // 2^24 against 2^25 - 1: bit 24 they share, bit 23 they do not
        throw std::runtime_error("2^24 and 2^25 - 1 should first differ at bit 23");
      Outputs r;
      for (const int4& c : counts) Append(r, std::vector<int>{c.x, c.y, c.z, c.w});
      return r;
    }));
#endif

#if __has_include("BoxFields_CPU.h")
Register boxFields(MakeCase<BoxFields>(
    "fields of arrays of structs (Box4f, structs of three and four 4-vector rows through pointers and a member vector) at the loop's index and a shuffled one",
    "box_fields.h/.cpp", 1e-5, CONFORMANCE_MAKERS(BoxFields), [](BoxFields& b) {
      const int n = 61;  // leaves a part of a gang of 4, 8 and 16 lanes
      std::vector<Box4f> boxes(n);
      std::vector<Stroke> strokes(n);
      std::vector<int> order(n);
      for (int i = 0; i < n; i++)
      {
        const float f = float(i);
        boxes[i].boxMin = float4(-f, 0.5f * f, 1.0f, 0.0f);
        boxes[i].boxMax = float4(f, 2.0f * f, 3.0f + f, 1.0f);
        strokes[i].from = float4(0.1f * f, 1.0f, -f, 0.0f);
        strokes[i].to = float4(f, 1.5f, f, 2.0f);
        strokes[i].tag = int4(i % 4, -1, 2, i % 3);
        order[i] = (7 * i + 3) % n;
      }
      std::vector<float4> out(n, float4(-1.0f));
      b.CommitDeviceData();
      b.Combine(n, boxes.data(), strokes.data(), order.data(), out.data());
      // A known answer: element 0 (order 3, i % 3 == 0). center (0, 0, 2, 0.5), far = box 3's max (3, 6, 6, 1),
      // along (0, 0.5, 0, 2) x tag 0 + 0, moved = swimmer 0 (0, 1, 0, 1) + vel x 0, tint = swimmer 3's colour,
      // then + from 0 x 2 (0, 2, 0, 0) + center.
      const float4 expected = float4(0.0f, 0.0f, 2.0f, 0.5f) + 0.25f * float4(3.0f, 6.0f, 6.0f, 1.0f) + float4(0.0f, 1.0f, 0.0f, 1.0f) +
                              float4(0.03f, 0.5f, 0.97f, 0.25f) + float4(0.0f, 2.0f, 0.0f, 0.0f) + float4(0.0f, 0.0f, 2.0f, 0.5f);
      for (int c = 0; c < 4; c++)
        if (std::abs(out[0][c] - expected[c]) > 1e-5f) throw std::runtime_error("element 0 should be the known answer");
      Outputs r;
      for (const float4& v : out) Append(r, std::vector<float>{v.x, v.y, v.z, v.w});
      return r;
    }));
#endif

#if __has_include("OldAtomics_CPU.h")
Register oldAtomics(MakeCase<OldAtomics>(
    "atomicAdd(a_out[i], v) and InterlockedAdd3f(array, offset, float3), the older spellings", "old_atomics.h/.cpp", 0.0,
    CONFORMANCE_MAKERS(OldAtomics), [](OldAtomics& a) {
      a.CommitDeviceData();
      const uint32_t bins = 10, threads = 6000;
      std::vector<int32_t> counts(bins, 5);
      std::vector<float> sums(bins * 4, 0.0f);
      a.Scatter(threads, counts.data(), sums.data(), bins);
      // Known answers: 600 threads per bin (7 and 10 are coprime), counts add i % 3 to the 5 there.
      int32_t total = 0;
      for (int32_t c : counts) total += c;
      if (total != int32_t(5 * bins) + 6000 / 3 * (0 + 1 + 2)) throw std::runtime_error("the counts should add up to 6050");
      for (uint32_t b = 0; b < bins; b++)
        if (sums[b * 4] != 600.0f || sums[b * 4 + 1] != 300.0f || sums[b * 4 + 3] != 0.0f)
          throw std::runtime_error("each bin should get 600 adds of (1, 0.5, i % 4) and nothing in its fourth float");
      Outputs r;
      Append(r, counts);
      Append(r, sums);
      return r;
    }));
#endif

}  // namespace
