// half4: colours stored as four 16-bit floats, converted on the way in and out.
#pragma once
#include "LiteMath.h"
#include <vector>
using LiteMath::float4;
using LiteMath::half4;

class HalfPack
{
public:
  virtual void Pack(int n, const float4* a_in [[size("n")]]);
  virtual void Unpack(int n, float4* a_out [[size("n")]]);
  virtual void CommitDeviceData() {}
  std::vector<half4> m_packed;

protected:
  void kernel1D_Pack(int n, const float4* a_in);
  void kernel1D_Unpack(int n, float4* a_out);
};
