#include "FastVectorOps.h"

#include "ScaleFast.spv.h"  // compiled from ScaleFast.comp at build time

void FastVectorOps::kernel1D_ScaleCmd(VkCommandBuffer a_cmd, int n, float factor, crossrt::BufferView data)
{
  if (m_scaleFast.Handle() == VK_NULL_HANDLE)
    m_scaleFast = crossrt::ComputePipeline(m_ctx, ScaleFast, sizeof(ScaleFast), 1, 8, "FastVectorOps::ScaleFast");
  struct { uint32_t n; float factor; } args{uint32_t(n), factor};
  m_scaleFast.Bind(a_cmd);
  m_scaleFast.PushBuffers(a_cmd, {data});
  m_scaleFast.PushConstants(a_cmd, &args, sizeof(args));
  vkCmdDispatch(a_cmd, (uint32_t(n) + 255) / 256, 1, 1);
  crossrt::ComputeBarrier(a_cmd);
  ++handWrittenDispatches;
}
