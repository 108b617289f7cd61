#include "red_pixels.h"

bool RedPixels::PixelIsRed(uint32_t a_pixelValue) const
{
  const uint32_t red = a_pixelValue & 0xFFu, green = (a_pixelValue >> 8) & 0xFFu, blue = (a_pixelValue >> 16) & 0xFFu;
  return red >= 233 && green <= 48 && blue <= 56;
}

void RedPixels::ProcessPixels(uint32_t* a_data, uint32_t a_dataSize)
{
  m_found.clear();
  kernel1D_FindRedPixels(a_data, a_dataSize);
  kernel1D_PaintRedPixelsToYellow(a_data);
}

void RedPixels::kernel1D_FindRedPixels(const uint32_t* a_data, uint32_t a_dataSize)
{
  m_redPixelsNum = 0;
  for (uint32_t i = 0; i < a_dataSize; i++)
  {
    if (PixelIsRed(a_data[i]))
    {
      PixelInfo info;
      info.index = i;
      info.value = a_data[i];
      m_found.push_back(info);
      m_redPixelsNum++;
    }
  }
}

void RedPixels::kernel1D_PaintRedPixelsToYellow(uint32_t* a_data)
{
  for (uint32_t i = 0; i < m_found.size(); i++)
    a_data[m_found[i].index] = m_found[i].value | 0x0000FF00u;
}
