#include "solver_loops.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace {
// The grid's initial temperature: a hot left edge, a warm spot, cold elsewhere.
float Initial(int x, int y, int w, int h)
{
  if (x == 0) return 100.0f;
  const int dx = x - w / 2, dy = y - h / 2;
  return dx * dx + dy * dy < 9 ? 40.0f : 0.0f;
}
}  // namespace

HeatDiffusion::HeatDiffusion(int a_width, int a_height) : m_width(a_width), m_height(a_height)
{
  m_cur.resize(size_t(a_width) * a_height);
  m_next.resize(m_cur.size());
  for (int y = 0; y < a_height; ++y)
    for (int x = 0; x < a_width; ++x)
      m_cur[y * a_width + x] = m_next[y * a_width + x] = Initial(x, y, a_width, a_height);
}

void HeatDiffusion::kernel2D_Diffuse(int a_width, int a_height)
{
  for (int y = 0; y < a_height; ++y)
    for (int x = 0; x < a_width; ++x)
    {
      const int i = y * a_width + x;
      float t = m_cur[i];
      if (x > 0 && x < a_width - 1 && y > 0 && y < a_height - 1)
        t = 0.25f * (m_cur[i - 1] + m_cur[i + 1] + m_cur[i - a_width] + m_cur[i + a_width]);
      m_next[i] = t;
      m_residual = std::max(m_residual, std::abs(t - m_cur[i]));
    }
}

void HeatDiffusion::Solve(int a_maxSteps, float a_tolerance)
{
  m_steps = 0;
  for (int step = 0; step < a_maxSteps; ++step)
  {
    m_residual = 0.0f;
    kernel2D_Diffuse(m_width, m_height);
    std::swap(m_cur, m_next);
    m_steps++;
    if (m_residual < a_tolerance)
      break;
  }
}

void HeatDiffusion::SolveChecked(int a_maxSteps, float a_tolerance, int a_checkEvery)
{
  m_steps = 0;
  while (m_steps < a_maxSteps)
  {
    m_residual = 0.0f;
    kernel2D_Diffuse(m_width, m_height);
    m_cur.swap(m_next);
    m_steps += 1;
    if (m_steps % a_checkEvery == 0 && m_residual < a_tolerance)
      return;
  }
}

void PingPong::kernel1D_Inc(int n)
{
  for (int i = 0; i < n; ++i)
  {
    const int self = m_a[i];  // names the generated code uses too, GLSL's and ISPC's
    const int programIndex = 1, task = self;
    m_b[i] = task + programIndex;
  }
}

void PingPong::kernel1D_Fill(int* a_out, int a_value, int n)
{
  for (int i = 0; i < n; ++i)
    a_out[i] = a_value;
}

void PingPong::kernel1D_Scale(const int* a_in, int* a_out, int a_factor, int n)
{
  for (int i = 0; i < n; ++i)
    a_out[i] = a_factor * a_in[i];
}

void PingPong::Run(int a_steps)
{
  const int n = int(m_a.size());
  for (int k = 0; k < a_steps; ++k)
  {
    kernel1D_Inc(n);
    std::swap(m_a, m_b);
  }
}

void PingPong::Twice()
{
  kernel1D_Scale(m_a.data(), m_b.data(), 2, int(m_b.size()));
  m_first = m_a[0] + m_b[0];
}
