// A class whose names are those the generated classes use for their own parts (issue 52): members
// named like the Vulkan class's device copies, pipelines, timers and context, a control function
// parameter named like the recorded command buffer, helpers named like the generated methods, and
// kernel locals named like the shaders' thread index and range test. The generated code keeps its
// own names under the reserved prefix crt_, so each of these must still mean the user's.
#pragma once
#include <vector>

class Ledger
{
public:
  Ledger(int a_size = 64);
  virtual ~Ledger() = default;
  virtual void CommitDeviceData() {}
  virtual void Run(int a_cmd, float a_scale);

  std::vector<float> m_vdata, m_images, m_pipelines;
  float m_ctx = 1.0f, m_times = 0.0f;
  int m_args = 0, m_recording = 0, m_scenes = 2, m_virtual = 3, m_hostTail_Run = 0, m_inOut_Run = 5, m_temporaries = 7;
  int m_threadState = 11, m_classDataBuffer = 13, m_gpuTimer = 17, m_partials = 19, m_executionMode = 23;

protected:
  void kernel1D_Weigh(int n, float a_scale);
  void kernel1D_Total(int n);
  int Synchronize() const { return m_scenes + m_virtual; }
  float UpdateMemberCmd(float x) const { return x * m_ctx; }
  int InitPipelines() const { return m_temporaries + m_threadState + m_classDataBuffer + m_gpuTimer + m_partials + m_executionMode; }
};
