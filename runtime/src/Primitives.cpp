// GPU versions of the library calls control functions may make (scans, sorts, copies, fills), and
// the indirect dispatch of kernels that run over what earlier kernels appended.
#include "crossrt/VulkanRuntime.h"

#include "Internal.h"

#include "indirect_groups.h"
#include "radix_histogram.h"
#include "radix_scatter.h"
#include "scan_add_float.h"
#include "scan_add_int.h"
#include "scan_add_uint.h"
#include "scan_blocks_float.h"
#include "scan_blocks_int.h"
#include "scan_blocks_uint.h"

#include <algorithm>

namespace crossrt {

namespace {
constexpr uint32_t kBlock = 1024;  // elements per workgroup of the scan shaders

// Groups for one pass, spread over y beyond the device's per-dimension limit.
void DispatchBlocks(VkCommandBuffer cmd, uint32_t blocks) {
  uint32_t x = std::min<uint32_t>(blocks, 65535), y = (blocks + x - 1) / x;
  vkCmdDispatch(cmd, x, y, 1);
}
}  // namespace

Scanner::Scanner(std::shared_ptr<VulkanContext> ctx) : ctx_(std::move(ctx)) {}

void Scanner::Init() {
  if (blocks_[0].Handle() != VK_NULL_HANDLE) return;  // pipelines are made on first use
  if (!ctx_->hasSubgroupArithmetic || ctx_->subgroupSize < 4)
    throw Error("GPU scan needs compute subgroup arithmetic with >= 4 lanes on '" + ctx_->DeviceName() + "'");
  blocks_[0] = ComputePipeline(ctx_, scan_blocks_uint, sizeof(scan_blocks_uint), 3, 12, "crossrt::scan_blocks(uint)");
  blocks_[1] = ComputePipeline(ctx_, scan_blocks_int, sizeof(scan_blocks_int), 3, 12, "crossrt::scan_blocks(int)");
  blocks_[2] = ComputePipeline(ctx_, scan_blocks_float, sizeof(scan_blocks_float), 3, 12, "crossrt::scan_blocks(float)");
  add_[0] = ComputePipeline(ctx_, scan_add_uint, sizeof(scan_add_uint), 2, 12, "crossrt::scan_add(uint)");
  add_[1] = ComputePipeline(ctx_, scan_add_int, sizeof(scan_add_int), 2, 12, "crossrt::scan_add(int)");
  add_[2] = ComputePipeline(ctx_, scan_add_float, sizeof(scan_add_float), 2, 12, "crossrt::scan_add(float)");
}

void Scanner::RecordCmd(VkCommandBuffer cmd, BufferView in, BufferView out, uint32_t n, bool inclusive, ElementType type,
                        uint32_t initBits) {
  if (n == 0) return;
  Init();
  const int t = int(type);
  // Scratch: one buffer of block totals per level (n/1024, n/1024^2, ...).
  std::vector<uint32_t> counts;
  for (uint32_t m = n; m > 1 || counts.empty(); m = (m + kBlock - 1) / kBlock) {
    counts.push_back(m);
    if (m <= kBlock) break;
  }
  if (levels_.size() < counts.size()) levels_.resize(counts.size());
  for (size_t l = 0; l < counts.size(); ++l)
    GrowScratch(ctx_, levels_[l].sums, 4ull * ((counts[l] + kBlock - 1) / kBlock), retired_);

  // Down: scan each level's blocks, collecting block totals into the next level.
  for (size_t l = 0; l < counts.size(); ++l) {
    const uint32_t m = counts[l], blocks = (m + kBlock - 1) / kBlock;
    const bool last = blocks == 1;
    struct { uint32_t n, inclusive, writeSums; } args{m, l == 0 && inclusive ? 1u : 0u, last ? 0u : 1u};
    BufferView src = l == 0 ? in : levels_[l - 1].sums.View();
    BufferView dst = l == 0 ? out : levels_[l - 1].sums.View();  // upper levels scan in place
    blocks_[t].Bind(cmd);
    blocks_[t].PushBuffers(cmd, {src, dst, levels_[l].sums.View()});
    blocks_[t].PushConstants(cmd, &args, sizeof(args));
    DispatchBlocks(cmd, blocks);
    ComputeBarrier(cmd);
  }
  // Up: add each block's offset, from the top level down; the initial value joins at level 0.
  for (size_t l = counts.size(); l-- > 0;) {
    const uint32_t m = counts[l], blocks = (m + kBlock - 1) / kBlock;
    const bool hasOffsets = blocks > 1;
    if (!hasOffsets && (l > 0 || initBits == 0)) continue;  // nothing to add
    struct { uint32_t n, hasOffsets, init; } args{m, hasOffsets ? 1u : 0u, l == 0 ? initBits : 0u};
    BufferView data = l == 0 ? out : levels_[l - 1].sums.View();
    add_[t].Bind(cmd);
    add_[t].PushBuffers(cmd, {data, levels_[l].sums.View()});
    add_[t].PushConstants(cmd, &args, sizeof(args));
    DispatchBlocks(cmd, blocks);
    ComputeBarrier(cmd);
  }
}

RadixSorter::RadixSorter(std::shared_ptr<VulkanContext> ctx) : ctx_(ctx), scanner_(ctx) {}

void RadixSorter::RecordCmd(VkCommandBuffer cmd, BufferView records, uint32_t n, SortKey key) {
  RecordCmd(cmd, records, n, key, {}, 0);
}

void RadixSorter::RecordCmd(VkCommandBuffer cmd, BufferView records, uint32_t n, SortKey key, BufferView counts,
                            uint32_t countOffset) {
  if (n <= 1) return;
  if (key.strideWords == 0 || key.keyWord >= key.strideWords)
    throw Error("RadixSorter: key word " + std::to_string(key.keyWord) + " outside records of " +
                std::to_string(key.strideWords) + " words");
  if (countOffset % 4 != 0) throw Error("RadixSorter: the count must be an aligned 32-bit word");
  if (histogram_.Handle() == VK_NULL_HANDLE) {  // pipelines are made on first use
    histogram_ = ComputePipeline(ctx_, radix_histogram, sizeof(radix_histogram), 3, 28, "crossrt::radix_histogram");
    scatter_ = ComputePipeline(ctx_, radix_scatter, sizeof(radix_scatter), 4, 28, "crossrt::radix_scatter");
  }
  const uint32_t tiles = (n + kBlock - 1) / kBlock;
  GrowScratch(ctx_, recordsTmp_, 4ull * key.strideWords * n, retired_);
  GrowScratch(ctx_, counts_, 4ull * 256 * tiles, retired_);
  const bool countOnGpu = counts.buffer != VK_NULL_HANDLE;
  const uint32_t keyMode = uint32_t(key.type) | (key.descending ? 4u : 0u) | (countOnGpu ? 8u : 0u);
  const BufferView count = countOnGpu ? counts : counts_.View();  // not read without the flag
  // Four passes ping-pong between the caller's buffer and scratch, ending in the caller's.
  BufferView r[2] = {records, recordsTmp_.View()};
  for (uint32_t pass = 0; pass < 4; ++pass) {
    const uint32_t src = pass % 2, dst = 1 - src;
    struct { uint32_t n, shift, tiles, stride, keyWord, keyMode, countWord; } args{
        n, 8 * pass, tiles, key.strideWords, key.keyWord, keyMode, countOffset / 4};
    histogram_.Bind(cmd);
    histogram_.PushBuffers(cmd, {r[src], counts_.View(), count});
    histogram_.PushConstants(cmd, &args, sizeof(args));
    DispatchBlocks(cmd, tiles);
    ComputeBarrier(cmd);
    scanner_.RecordCmd(cmd, counts_.View(), counts_.View(), 256 * tiles, false, ElementType::Uint);
    scatter_.Bind(cmd);
    scatter_.PushBuffers(cmd, {r[src], r[dst], counts_.View(), count});
    scatter_.PushConstants(cmd, &args, sizeof(args));
    DispatchBlocks(cmd, tiles);
    ComputeBarrier(cmd);
  }
}

void CopyCmd(VkCommandBuffer cmd, BufferView src, BufferView dst, VkDeviceSize bytes) {
  if (bytes == 0) return;
  VkBufferCopy region{src.offset, dst.offset, bytes};
  vkCmdCopyBuffer(cmd, src.buffer, dst.buffer, 1, &region);
  TransferToComputeBarrier(cmd);
}

void FillCmd(VkCommandBuffer cmd, BufferView dst, VkDeviceSize bytes, uint32_t bits) {
  if (bytes == 0) return;
  vkCmdFillBuffer(cmd, dst.buffer, dst.offset, bytes, bits);
  TransferToComputeBarrier(cmd);
}

void ZeroCmd(VkCommandBuffer cmd, const Buffer& buffer, VkDeviceSize bytes, const char* what) {
  if (bytes > buffer.Size())
    throw Error(std::string(what) + " has grown since CommitDeviceData(): its device copy holds " + std::to_string(buffer.Size()) +
                " bytes, not " + std::to_string(bytes) + " (call CommitDeviceData() after resizing it)");
  FillCmd(cmd, buffer.View(), bytes, 0u);
}

IndirectDispatcher::IndirectDispatcher(std::shared_ptr<VulkanContext> ctx, uint32_t slots)
    : ctx_(std::move(ctx)), slots_(slots) {
  // Slots are bound as storage buffers: each starts at the device's storage offset alignment.
  const VkDeviceSize align = std::max<VkDeviceSize>(16, ctx_->properties.limits.minStorageBufferOffsetAlignment);
  stride_ = (sizeof(VkDispatchIndirectCommand) + align - 1) / align * align;
  groups_ = ComputePipeline(ctx_, indirect_groups, sizeof(indirect_groups), 2, 16, "crossrt::indirect_groups");
  args_ = Buffer(ctx_, stride_ * std::max(1u, slots), VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
}

void IndirectDispatcher::PrepareCmd(VkCommandBuffer cmd, uint32_t slot, BufferView counts, uint32_t sizeOffset,
                                    uint32_t capacityOffset, uint32_t groupSize) {
  if (slot >= slots_) throw Error("IndirectDispatcher: slot " + std::to_string(slot) + " of " + std::to_string(slots_));
  if (sizeOffset % 4 != 0 || capacityOffset % 4 != 0 || groupSize == 0)
    throw Error("IndirectDispatcher: counts must be aligned 32-bit words, groups non-empty");
  // An earlier dispatch of this slot must have read its groups before they are rewritten.
  auto done = VkInit<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  done.srcAccessMask = VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
  done.dstAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &done, 0,
                       nullptr, 0, nullptr);
  const VkDeviceSize at = stride_ * slot;
  struct { uint32_t sizeWord, capacityWord, groupSize, maxGroupsX; } args{sizeOffset / 4, capacityOffset / 4, groupSize, 65535};
  groups_.Bind(cmd);
  groups_.PushBuffers(cmd, {counts, args_.View(at, sizeof(VkDispatchIndirectCommand))});
  groups_.PushConstants(cmd, &args, sizeof(args));
  vkCmdDispatch(cmd, 1, 1, 1);
  auto ready = VkInit<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  ready.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  ready.dstAccessMask = VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT, 0, 1, &ready, 0,
                       nullptr, 0, nullptr);
}

void IndirectDispatcher::DispatchCmd(VkCommandBuffer cmd, uint32_t slot) const {
  vkCmdDispatchIndirect(cmd, args_.Handle(), stride_ * slot);
}

}  // namespace crossrt
