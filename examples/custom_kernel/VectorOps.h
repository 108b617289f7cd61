// A plain class with two kernels. FastVectorOps (FastVectorOps.h) derives from the generated
// VectorOps_Vulkan and replaces one kernel with hand-written Vulkan; regeneration keeps it working.
#pragma once

class VectorOps
{
public:
  virtual ~VectorOps() = default;
  // data[i] = data[i] * m_factor + m_offset
  virtual void Process(int n, [[crossrt::size("n")]] float* data);
  virtual void CommitDeviceData() {}

  float m_factor = 3.0f;
  float m_offset = 1.0f;

protected:
  void kernel1D_Scale(int n, float factor, float* data);
  void kernel1D_Offset(int n, float* data);
};
