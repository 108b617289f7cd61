#include "FastVectorOps.h"

#include "ScaleFast.spv.h"  // compiled from ScaleFast.comp at build time

void FastVectorOps::kernel1D_ScaleCmd(VkCommandBuffer crt_cmd, int n, float factor, crossrt::BufferView data)
{
  if (m_scaleFast.Handle() == VK_NULL_HANDLE)
    m_scaleFast = crossrt::ComputePipeline(crt_ctx, ScaleFast, sizeof(ScaleFast), 1, 8, "FastVectorOps::ScaleFast");
  struct { uint32_t n; float factor; } args{uint32_t(n), factor};
  m_scaleFast.Bind(crt_cmd);
  m_scaleFast.PushBuffers(crt_cmd, {data});
  m_scaleFast.PushConstants(crt_cmd, &args, sizeof(args));
  vkCmdDispatch(crt_cmd, (uint32_t(n) + 255) / 256, 1, 1);
  crossrt::ComputeBarrier(crt_cmd);
  ++handWrittenDispatches;
}
