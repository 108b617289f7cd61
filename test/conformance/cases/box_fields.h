// Arrays of structs read a field at a time, as users write them: LiteMath's Box4f through a pointer
// (two 16-byte rows), a struct of three rows through a pointer (float4, float4, int4) and a member
// vector of a struct of four (float4 x3, uint4), each read at the loop's index (neighbouring threads
// read neighbouring elements) and at a shuffled one, over a count that leaves a part of a SIMD gang.
#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <vector>

using LiteMath::Box4f;
using LiteMath::float4;
using LiteMath::int4;
using LiteMath::uint4;

struct Stroke
{
  float4 from;
  float4 to;
  int4 tag;  // weights of the stroke's length: tag.x + tag.w
};

struct Swimmer
{
  float4 pos;
  float4 vel;
  float4 color;
  uint4 ids;  // ids.y scales the swimmer's half step
};

class BoxFields
{
public:
  BoxFields();
  virtual ~BoxFields() = default;
  virtual void Combine(int n, const Box4f* boxes [[size("n")]], const Stroke* strokes [[size("n")]], const int* order [[size("n")]],
                       float4* out [[size("n")]]);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Combine(int n, const Box4f* boxes, const Stroke* strokes, const int* order, float4* out);

  std::vector<Swimmer> m_swimmers;
};
