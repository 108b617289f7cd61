#include "projector.h"

#include <cmath>

float4x4 perspectiveMatrix(float fovy, float aspect, float zNear, float zFar)
{
  const float f = 1.0f / std::tan(fovy * 0.5f);  // radians, unlike LiteMath's (degrees)
  float4x4 m;
  m.set_col(0, float4(f / aspect, 0, 0, 0));
  m.set_col(1, float4(0, f, 0, 0));
  m.set_col(2, float4(0, 0, (zFar + zNear) / (zNear - zFar), -1));
  m.set_col(3, float4(0, 0, 2 * zFar * zNear / (zNear - zFar), 0));
  return m;
}

Projector::Projector() { m_proj = perspectiveMatrix(1.0f, 1.5f, 0.1f, 100.0f); }

void Projector::Project(int n, const float4* a_in, float4* a_out) { kernel1D_Project(n, a_in, a_out); }

void Projector::kernel1D_Project(int n, const float4* a_in, float4* a_out)
{
  for (int i = 0; i < n; i++)
  {
    float4x4 proj = m_proj;  // its last row set per point, as kernel_slicer's test 031 writes rows
    const float4 lastRow(0.0f, 0.0f, -1.0f, 0.001f * float(i % 5));
    proj.set_row(3, lastRow);
    const float4 clip = proj * a_in[i];
    a_out[i] = clip / clip.w;
  }
}
