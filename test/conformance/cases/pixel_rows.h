// Whole float4 and int4 pixels written through pointers: a row in order, and the same row mirrored
// (each thread writes another thread's pixel), for a length that no SIMD width divides; and a
// pixel and an element of a local array updated through an index with a side effect (rows[slot++] += v).
#pragma once
#include "LiteMath.h"
using namespace LiteMath;

class PixelRows
{
public:
  virtual void Shade(int n, const float4* a_in [[size("n")]], float4* a_rows [[size("n")]], float4* a_mirrored [[size("n")]],
                     int4* a_cells [[size("n")]]);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Shade(int n, const float4* a_in, float4* a_rows, float4* a_mirrored, int4* a_cells);
};
