// A user's class whose GPU kernels are compiled for its settings (Specialize.h), written as a new
// user would: in a file not named after the class, a static helper in the .cpp, a count set up
// before the kernel and a share written after it. It maps HDR colours to display values with one of
// three curves; the curve, the white point, the banding and whether negative values are clamped are
// CRT_SPECIALIZE (an enum, a float, an int and a bool), the exposure is not.
// test/equivalence/test_specialize.cpp runs it on every backend, changing the settings between calls.
#pragma once
#include "LiteMath.h"
#include "Specialize.h"

#include <cstdint>
#include <vector>

enum class ToneCurve : uint32_t
{
  Linear,
  Reinhard,
  Aces,
};

class ToneMapper
{
public:
  ToneMapper() = default;
  virtual ~ToneMapper() = default;

  // ldr[i] = the curve of hdr[i] * m_exposure; m_clipped counts the inputs whose luminance reaches
  // the white point, m_clippedShare is their share of n.
  virtual void Map(int n, [[crossrt::size("n")]] const LiteMath::float4* hdr, [[crossrt::size("n")]] LiteMath::float4* ldr);
  virtual void CommitDeviceData() {}

  CRT_SPECIALIZE ToneCurve m_curve = ToneCurve::Aces;
  CRT_SPECIALIZE float m_whitePoint = 4.0f;
  CRT_SPECIALIZE int m_bands = 0;  // 0: smooth; else the output takes this many levels
  CRT_SPECIALIZE bool m_clampNegative = true;
  float m_exposure = 1.0f;
  uint32_t m_clipped = 0;
  float m_clippedShare = 0.0f;

protected:
  void kernel1D_Map(int n, const LiteMath::float4* hdr, LiteMath::float4* ldr);
};
