// Iterative solvers as users write them: host code between kernel calls reads what the kernels
// reduced (a residual), swaps two member vectors, counts steps and stops early (issue 52). Two
// classes in one pair of files, neither named after them.
#pragma once
#include <cstdint>
#include <vector>

// Jacobi steps of the heat equation on a grid with fixed edges, until the largest change of a step
// is below a tolerance.
class HeatDiffusion
{
public:
  HeatDiffusion(int a_width = 24, int a_height = 16);
  virtual ~HeatDiffusion() = default;
  virtual void CommitDeviceData() {}

  // Steps until the residual is below a_tolerance, at most a_maxSteps of them.
  virtual void Solve(int a_maxSteps, float a_tolerance);
  // The same, looking at the residual only every a_checkEvery steps.
  virtual void SolveChecked(int a_maxSteps, float a_tolerance, int a_checkEvery);

  int Steps() const { return m_steps; }
  float Residual() const { return m_residual; }
  const std::vector<float>& Temperature() const { return m_cur; }

protected:
  void kernel2D_Diffuse(int a_width, int a_height);

  int m_width, m_height;
  std::vector<float> m_cur, m_next;
  float m_residual = 0.0f;
  int m_steps = 0;
};

// The two silent cases: a swap of member vectors between kernel calls, and a member's
// data() handed to a kernel that writes it.
class PingPong
{
public:
  PingPong(int a_size = 100) : m_a(a_size, 0), m_b(a_size, 0) {}
  virtual ~PingPong() = default;
  virtual void CommitDeviceData() {}

  // a_steps times: m_b = m_a + 1, then swap them; m_a ends as a_steps.
  virtual void Run(int a_steps);
  // m_a[i] = a_value, through m_a.data().
  virtual void Fill(int a_value) { kernel1D_Fill(m_a.data(), a_value, int(m_a.size())); }
  // m_b = 2 * m_a through both data(), then the host adds the first element of each.
  virtual void Twice();
  // m_a[i] = a_value, then a swap after the last kernel: m_b holds a_value.
  virtual void FillAndSwap(int a_value)
  {
    kernel1D_Fill(m_a.data(), a_value, int(m_a.size()));
    m_a.swap(m_b);
  }

  // m_a[i] = a_value, then the host changes its first element after the last kernel: the next
  // call's kernels see the host's value (found by the differential tester: Diff8).
  virtual void FillThenSet(int a_value)
  {
    kernel1D_Fill(m_a.data(), a_value, int(m_a.size()));
    m_a[0] = -a_value;
  }

  std::vector<int> m_a, m_b;
  int m_first = 0;

protected:
  void kernel1D_Inc(int n);
  void kernel1D_Fill(int* a_out, int a_value, int n);
  void kernel1D_Scale(const int* a_in, int* a_out, int a_factor, int n);
};
