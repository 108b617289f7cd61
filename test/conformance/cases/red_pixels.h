// push_back in a kernel, then a kernel over what was appended (dispatched indirectly), as in
// kernel_slicer's 08_push_back_red_pixels.
#pragma once
#include "LiteMath.h"
#include <cstdint>
#include <vector>

struct PixelInfo
{
  uint32_t index;
  uint32_t value;
};

class RedPixels
{
public:
  RedPixels() { m_found.reserve(1 << 16); }
  virtual void ProcessPixels(uint32_t* a_data [[size("a_dataSize")]], uint32_t a_dataSize);
  virtual void CommitDeviceData() {}
  std::vector<PixelInfo> m_found;
  uint32_t m_redPixelsNum = 0;

protected:
  void kernel1D_FindRedPixels(const uint32_t* a_data, uint32_t a_dataSize);
  void kernel1D_PaintRedPixelsToYellow(uint32_t* a_data);
  bool PixelIsRed(uint32_t a_pixelValue) const;
};
