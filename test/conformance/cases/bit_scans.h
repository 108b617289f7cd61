// Bit scans and counts of 32-bit words, as users write them with GCC's and Clang's builtins: the
// leading and trailing zeros (guarded, as __builtin_clz(0) and __builtin_ctz(0) are undefined), the
// set bits, and the highest bit two neighbouring words share (the prefix an LBVH splits on), in a
// static helper and inline.
#pragma once
#include "LiteMath.h"
#include <cstdint>

using LiteMath::int4;

class BitScans
{
public:
  BitScans() = default;
  virtual ~BitScans() = default;
  virtual void Scan(int n, const uint32_t* words [[size("n")]], int4* counts [[size("n")]]);
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Scan(int n, const uint32_t* words, int4* counts);
};
