// kernel_slicer's RTV form as its samples write it: the per-thread function MainFunc carries the
// size of the output (in its thread counts, tidX by tidY), and the ...Block control function that
// runs it over every pixel, a_numPasses times, has no size of its own. MainFunc keeps a constant in
// a local, returns early where a kernel says so (if (!kernel_InitRay(...)) return;) and leaves a
// loop on a test of its own local (if (done != 0u) break;), as kernel_slicer's samples do.
#pragma once
#include "LiteMath.h"
#include <cstdint>

using LiteMath::float4;

class PixelBlock
{
public:
  void MainFunc(uint32_t tidX, uint32_t tidY, uint32_t* out_color __attribute__((size("tidX", "tidY"))));
  virtual void MainFuncBlock(uint32_t tidX, uint32_t tidY, uint32_t* out_color, uint32_t a_numPasses = 1);
  virtual void CommitDeviceData() {}

  bool kernel_InitRay(float4* rayDir, uint32_t tidX, uint32_t tidY);
  void kernel_Bounce(float4* rayDir, uint32_t* done, uint32_t tidX, uint32_t tidY);
  void kernel_Shade(const float4* rayDir, const float* exposure, uint32_t* out_color, uint32_t tidX, uint32_t tidY, uint32_t alpha);

  uint32_t m_width = 48;  // the image's row length, which the kernels index by
};
