// kernel_slicer's block expansion (its test 030): a kernelBE1D_ template over the block size whose
// blocks share a local array between [[parallel]] loops, with a one-thread step between them. The
// CPU backend runs a block per core (test/equivalence/test_block_kernels.cpp); the GPU and ISPC
// backends refuse it at the kernel.
#pragma once
#include "LiteMath.h"

using LiteMath::uint;

class BlockSums
{
public:
  virtual ~BlockSums() = default;
  // out[b * 64 + i] = in[b * 64] + ... + in[b * 64 + i] + the block's first element (a block-wise scan).
  virtual void Scan(uint numElements, const float* in [[size("numElements")]], float* out [[size("numElements")]]);
  virtual void CommitDeviceData() {}

  template <uint bsize>
  void kernelBE1D_Scan(uint blockNum, const float* in, float* out);
};
