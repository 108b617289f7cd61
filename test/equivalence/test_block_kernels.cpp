// kernel_slicer's block expansion on the CPU backend: BlockSums_CPU runs the blocks of a
// kernelBE1D_ template on all cores and gets the original's block-wise scans exactly.
#include "BlockSums.h"
#include "BlockSums_CPU.h"

#include <catch2/catch.hpp>

#include <vector>

TEST_CASE("kernel_slicer's block expansion (kernelBE1D_ templates) on the CPU backend", "[equivalence][blocks]")
{
  const uint n = 64 * 37;
  std::vector<float> in(n);
  for (uint i = 0; i < n; ++i) in[i] = float(int(i * 7919u % 97u) - 48) * 0.125f;
  BlockSums original;
  std::vector<float> expected(n, -1.0f);
  original.Scan(n, in.data(), expected.data());
  // The original, against the test's own scan of block 5.
  float sum = 0.0f;
  for (uint i = 0; i < 64; ++i)
  {
    sum += in[5 * 64 + i];
    REQUIRE(expected[5 * 64 + i] == sum + in[5 * 64]);
  }
  auto cpu = CreateBlockSums_CPU();
  std::vector<float> got(n, -1.0f);
  cpu->Scan(n, in.data(), got.data());
  REQUIRE(got == expected);
}
