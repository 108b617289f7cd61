#include "pixel_rows.h"

void PixelRows::Shade(int n, const float4* a_in, float4* a_rows, float4* a_mirrored, int4* a_cells)
{
  kernel1D_Shade(n, a_in, a_rows, a_mirrored, a_cells);
}

void PixelRows::kernel1D_Shade(int n, const float4* a_in, float4* a_rows, float4* a_mirrored, int4* a_cells)
{
  for (int i = 0; i < n; i++)
  {
    const float4 c = a_in[i];
    a_rows[i] = c * 0.5f + float4(1.0f, 2.0f, 3.0f, 4.0f);
    a_mirrored[n - 1 - i] = float4(c.w, c.z, c.y, c.x);
    int slot = i;
    a_rows[slot++] += float4(0.0f, 0.0f, 0.0f, 0.5f);  // the address once: slot is i + 1 after it
    float4 sums[2] = {c, float4(0.0f)};
    int next = i % 2;
    sums[next++] += float4(3.0f, 1.0f, 1.0f, 1.0f);  // a local array's element, by a per-thread index: once too
    a_cells[i] = int4(i, -i, int(c.x) + int(sums[0].x + 2.0f * sums[1].x), slot + 10 * next);
  }
}
