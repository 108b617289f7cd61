#include "names_in_use.h"

Ledger::Ledger(int a_size) : m_vdata(a_size), m_images(a_size), m_pipelines(a_size)
{
  for (int i = 0; i < a_size; ++i)
  {
    m_vdata[i] = float(i % 5);
    m_pipelines[i] = float(i % 3);
  }
}

void Ledger::kernel1D_Weigh(int n, float a_scale)
{
  for (int i = 0; i < n; ++i)
  {
    const int threadId = i % 3, groupId = i / 7;
    const bool inRange = threadId + groupId > 2;
    const float self = m_vdata[i] * a_scale * m_ctx;
    m_images[i] = inRange ? self + float(m_scenes) : self - float(m_virtual) + m_pipelines[i];
  }
}

void Ledger::kernel1D_Total(int n)
{
  for (int i = 0; i < n; ++i)
    m_times += m_images[i];
}

void Ledger::Run(int a_cmd, float a_scale)
{
  m_recording = a_cmd + InitPipelines();
  kernel1D_Weigh(int(m_vdata.size()), UpdateMemberCmd(a_scale));
  m_times = 0.0f;
  kernel1D_Total(int(m_images.size()));
  // After the last kernel: the total, and a vector the kernels read changed for the next call.
  m_args = Synchronize() + int(m_times);
  m_pipelines[0] = m_times;
  m_hostTail_Run = m_inOut_Run + a_cmd;
}
