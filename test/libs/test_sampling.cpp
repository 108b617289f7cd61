// litept's random numbers (Sampling.h): the 4D Sobol points against the sequence's published first
// values, the Owen scramble as a permutation, and the stratification that makes them worth having: a
// pixel's first 2^m samples of a group form a (0, m, 2)-net in its first two numbers and hit every
// 1/2^m interval once in each number, for any pixel and group of the vertices that draw Sobol points.
#include "Sampling.h"

#include <catch2/catch.hpp>

#include <set>
#include <vector>

using namespace LiteMath;
using namespace litept;

TEST_CASE("sampling: Sobol4 gives the Sobol sequence's first points", "[sampling]")
{
  // The first eight points of dimensions 1-4 of Joe and Kuo's Sobol sequence, times 8, worked out by
  // hand: x_i is the XOR of the direction numbers v_k = m_k / 2^k of i's set bits, with m = (1, 1,
  // 1), (1, 3, 5), (1, 3, 3) and (1, 3, 1) from each dimension's polynomial and initial m.
  const uint32_t expected[8][4] = {{0, 0, 0, 0}, {4, 4, 4, 4}, {2, 6, 6, 6}, {6, 2, 2, 2},
                                   {1, 5, 3, 1}, {5, 1, 7, 5}, {3, 3, 5, 7}, {7, 7, 1, 3}};
  for (uint32_t i = 0; i < 8; ++i)
  {
    const uint4 p = Sobol4(i);
    INFO("index " << i);
    CHECK(p.x >> 29u == expected[i][0]);
    CHECK(p.y >> 29u == expected[i][1]);
    CHECK(p.z >> 29u == expected[i][2]);
    CHECK(p.w >> 29u == expected[i][3]);
  }
}

TEST_CASE("sampling: the Owen scramble permutes the values of every prefix block", "[sampling]")
{
  // Scrambling maps [k 2^m, (k + 1) 2^m) onto an aligned block of the same size, one to one: the
  // low m bits are permuted, the high ones flipped together.
  for (uint32_t seed : {0u, 1u, 0xDEADBEEFu})
  {
    std::set<uint32_t> values, blocks;
    for (uint32_t i = 0; i < 1024u; ++i)
    {
      const uint32_t s = OwenScramble(i, seed);
      values.insert(s);
      blocks.insert(s >> 10u);
    }
    CHECK(values.size() == 1024u);
    CHECK(blocks.size() == 1u);
  }
}

TEST_CASE("sampling: a pixel's first 2^m samples are stratified", "[sampling]")
{
  const uint32_t m = 8u, n = 1u << m;
  for (uint32_t pixel : {0u, 12345u})
    for (uint32_t bounce = 0; bounce < kSobolVertices; ++bounce)
      for (uint32_t slot : {0u, 2u})
      {
        std::vector<float4> u(n);
        for (uint32_t i = 0; i < n; ++i)
          u[i] = Random4(pixel, i, bounce, slot);
        INFO("pixel " << pixel << ", bounce " << bounce << ", slot " << slot);
        // Every 1D interval [j / n, (j + 1) / n) holds one sample, in each of the four numbers.
        for (int c = 0; c < 4; ++c)
        {
          std::set<uint32_t> cells;
          for (const float4& v : u)
            cells.insert(uint32_t(v[c] * float(n)));
          CHECK(cells.size() == n);
        }
        // Every elementary interval of area 1 / n, 2^a by 2^(m - a), holds one sample of (x, y).
        for (uint32_t a = 0; a <= m; ++a)
        {
          std::set<uint32_t> cells;
          for (const float4& v : u)
            cells.insert(uint32_t(v.x * float(1u << a)) * (1u << (m - a)) + uint32_t(v.y * float(1u << (m - a))));
          CHECK(cells.size() == n);
        }
      }
}

TEST_CASE("sampling: pixels and groups draw different numbers", "[sampling]")
{
  // The same sample index in neighbouring pixels, vertices and groups: no two agree.
  std::set<uint32_t> firsts;
  for (uint32_t pixel = 0; pixel < 16u; ++pixel)
    for (uint32_t bounce = 0; bounce < 4u; ++bounce)
      for (uint32_t slot = 0; slot < 3u; ++slot)
        firsts.insert(uint32_t(Random4(pixel, 3u, bounce, slot).x * 16777216.0f));
  CHECK(firsts.size() == 16u * 4u * 3u);
}
