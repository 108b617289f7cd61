// GpuTimer: named intervals measured with timestamp queries.
#include "crossrt/VulkanRuntime.h"
#include "Internal.h"

#include <utility>

namespace crossrt {

GpuTimer::GpuTimer(std::shared_ptr<VulkanContext> ctx, uint32_t maxQueries) : ctx_(std::move(ctx)) {
  if (!ctx_ || maxQueries == 0) return;
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(ctx_->physicalDevice, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(ctx_->physicalDevice, &n, families.data());
  uint32_t bits = ctx_->queueFamily < n ? families[ctx_->queueFamily].timestampValidBits : 0;
  if (bits == 0) return;  // no timestamps on this queue: every time reads as 0
  validMask_ = bits >= 64 ? ~uint64_t(0) : ((uint64_t(1) << bits) - 1);

  auto info = VkInit<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = maxQueries;
  Check(vkCreateQueryPool(ctx_->device, &info, nullptr, &pool_), "vkCreateQueryPool");
  maxQueries_ = maxQueries;
}

GpuTimer::GpuTimer(GpuTimer&& other) noexcept { *this = std::move(other); }

GpuTimer& GpuTimer::operator=(GpuTimer&& other) noexcept {
  if (this != &other) {
    Release();
    ctx_ = std::move(other.ctx_);
    pool_ = std::exchange(other.pool_, VK_NULL_HANDLE);
    maxQueries_ = std::exchange(other.maxQueries_, 0);
    used_ = std::exchange(other.used_, 0);
    validMask_ = std::exchange(other.validMask_, 0);
    intervals_ = std::move(other.intervals_);
    lastMs_ = std::move(other.lastMs_);
  }
  return *this;
}

GpuTimer::~GpuTimer() { Release(); }

void GpuTimer::Release() noexcept {
  if (ctx_ && pool_) vkDestroyQueryPool(ctx_->device, pool_, nullptr);
  pool_ = VK_NULL_HANDLE;
  ctx_.reset();
}

void GpuTimer::Reset(VkCommandBuffer cmd) {
  if (!pool_) return;
  vkCmdResetQueryPool(cmd, pool_, 0, maxQueries_);
  used_ = 0;
  intervals_.clear();
}

void GpuTimer::Begin(VkCommandBuffer cmd, const std::string& name) {
  if (!pool_ || used_ + 2 > maxQueries_) return;  // keep room for the matching End; overflow is just not timed
  vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, pool_, used_);
  intervals_.push_back(Interval{name, used_, UINT32_MAX});
  ++used_;
}

void GpuTimer::End(VkCommandBuffer cmd, const std::string& name) {
  if (!pool_ || used_ >= maxQueries_) return;
  // Close the most recent open interval of that name.
  for (auto it = intervals_.rbegin(); it != intervals_.rend(); ++it) {
    if (it->end == UINT32_MAX && it->name == name) {
      vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, pool_, used_);
      it->end = used_++;
      return;
    }
  }
}

void GpuTimer::Collect() {
  if (!pool_ || used_ == 0) return;
  // Value + availability per query: no WAIT flag, so an unsubmitted command buffer cannot hang us.
  std::vector<uint64_t> data(size_t(used_) * 2);
  VkResult r = vkGetQueryPoolResults(ctx_->device, pool_, 0, used_, data.size() * sizeof(uint64_t), data.data(),
                                     2 * sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT);
  if (r != VK_NOT_READY) Check(r, "vkGetQueryPoolResults");

  const double nsPerTick = ctx_->properties.limits.timestampPeriod;
  std::unordered_map<std::string, double> sums;
  for (const Interval& iv : intervals_) {
    if (iv.end == UINT32_MAX) continue;
    const uint64_t* b = &data[size_t(iv.begin) * 2];
    const uint64_t* e = &data[size_t(iv.end) * 2];
    if (!b[1] || !e[1]) continue;  // not available
    uint64_t ticks = ((e[0] & validMask_) - (b[0] & validMask_)) & validMask_;  // wrap-around safe
    sums[iv.name] += double(ticks) * nsPerTick * 1e-6;
  }
  for (const auto& kv : sums) lastMs_[kv.first] = static_cast<float>(kv.second);
  intervals_.clear();
}

float GpuTimer::LastMs(const std::string& name) const {
  auto it = lastMs_.find(name);
  return it == lastMs_.end() ? 0.0f : it->second;
}

}  // namespace crossrt
