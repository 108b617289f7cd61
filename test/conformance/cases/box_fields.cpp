#include "box_fields.h"

#include <cmath>

BoxFields::BoxFields()
{
  for (int i = 0; i < 64; i++)
  {
    const float f = float(i);
    Swimmer s;
    s.pos = float4(std::sin(f), std::cos(0.7f * f), 0.1f * f, 1.0f);
    s.vel = float4(0.5f, -0.25f * f, 0.0f, 2.0f);
    s.color = float4(0.01f * f, 0.5f, 1.0f - 0.01f * f, 0.25f);
    s.ids = uint4(uint32_t(i), uint32_t(i % 5), uint32_t(3 * i), 7u);
    m_swimmers.push_back(s);
  }
}

// The centre of a box.
static float4 Center(const Box4f& box) { return 0.5f * (box.boxMin + box.boxMax); }

void BoxFields::Combine(int n, const Box4f* boxes, const Stroke* strokes, const int* order, float4* out)
{
  kernel1D_Combine(n, boxes, strokes, order, out);
}

void BoxFields::kernel1D_Combine(int n, const Box4f* boxes, const Stroke* strokes, const int* order, float4* out)
{
  for (int i = 0; i < n; i++)
  {
    const float4 center = 0.5f * (boxes[i].boxMin + boxes[i].boxMax);
    const float4 far = boxes[order[i]].boxMax;  // another thread's element
    const float4 along = strokes[i].to - strokes[i].from;
    const int4 tag = strokes[i].tag;
    const float4 moved = m_swimmers[i].pos + m_swimmers[i].vel * (0.5f * float(m_swimmers[i].ids.y));
    const float4 tint = m_swimmers[order[i]].color;
    float4 result = center + 0.25f * far + along * float(tag.x + tag.w) + moved + tint;
    if (i % 3 == 0)  // a field read where only some threads go
      result += strokes[i].from * 2.0f + Center(boxes[i]);
    out[i] = result;
  }
}
