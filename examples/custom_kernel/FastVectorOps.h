// The user's own subclass of the generated class: it overrides one kernel's ...Cmd with a
// hand-written shader. It lives in the user's source tree, so regeneration never touches it.
#pragma once
#include "VectorOps_Vulkan.h"

class FastVectorOps : public VectorOps_Vulkan
{
public:
  using VectorOps_Vulkan::VectorOps_Vulkan;
  int handWrittenDispatches = 0;

protected:
  void kernel1D_ScaleCmd(VkCommandBuffer crt_cmd, int n, float factor, crossrt::BufferView data) override;
  crossrt::ComputePipeline m_scaleFast;  // created on first use (constructors cannot call overrides)
};
