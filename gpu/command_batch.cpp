#include "gpu/command_batch.h"

#include <algorithm>
#include <utility>

#include "gpu/buffer.h"
#include "gpu/check.h"
#include "gpu/compute_pipeline.h"
#include "gpu/context.h"

namespace sdfstream::gpu {
namespace {

// DRAW_INDIRECT: dispatchIndirect reads its group counts from a buffer an earlier pass wrote.
constexpr VkPipelineStageFlags kWorkStages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT |
                                             VK_PIPELINE_STAGE_TRANSFER_BIT |
                                             VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT;
constexpr VkAccessFlags kWrites = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
constexpr VkAccessFlags kReadsWrites = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                                       VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                                       VK_ACCESS_INDIRECT_COMMAND_READ_BIT;

// A global memory barrier: cheaper to reason about than per-buffer barriers and, for compute
// work on one queue, no slower on current drivers.
void memoryBarrier(VkCommandBuffer cb, VkPipelineStageFlags srcStages, VkAccessFlags srcAccess,
                   VkPipelineStageFlags dstStages, VkAccessFlags dstAccess) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = srcAccess;
  barrier.dstAccessMask = dstAccess;
  vkCmdPipelineBarrier(cb, srcStages, dstStages, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

std::uint32_t groups(std::uint32_t threads, std::uint32_t size) {
  return threads / size + (threads % size != 0);  // no overflow near UINT32_MAX
}

}  // namespace

CommandBatch::CommandBatch(Context& ctx, std::uint32_t maxPasses)
    : ctx_(&ctx), maxPasses_(maxPasses) {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = ctx.commandPool();
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  SDFSTREAM_VK(vkAllocateCommandBuffers(ctx.device(), &alloc, &commandBuffer_));
  try {
    createQueryPool();
  } catch (...) {
    vkFreeCommandBuffers(ctx.device(), ctx.commandPool(), 1, &commandBuffer_);
    throw;
  }
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  SDFSTREAM_VK(vkBeginCommandBuffer(commandBuffer_, &begin));
  beginRecording();
}

CommandBatch::CommandBatch(Context& ctx, VkCommandBuffer callerCommandBuffer,
                           std::uint32_t maxPasses)
    : ctx_(&ctx),
      commandBuffer_(callerCommandBuffer),
      maxPasses_(maxPasses),
      ownsCommandBuffer_(false) {
  SDFSTREAM_GPU_CHECK(callerCommandBuffer != VK_NULL_HANDLE, "recordInto a null command buffer");
  createQueryPool();
  beginRecording();
}

void CommandBatch::createQueryPool() {
  if (maxPasses_ == 0 || !ctx_->timestampsSupported()) return;
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = 2 * maxPasses_;
  SDFSTREAM_VK(vkCreateQueryPool(ctx_->device(), &info, nullptr, &queryPool_));
}

void CommandBatch::beginRecording() {
  ++ctx_->openBatches_;
  if (queryPool_) vkCmdResetQueryPool(commandBuffer_, queryPool_, 0, 2 * maxPasses_);
  // Earlier submissions on this queue (or the caller's earlier commands) are ordered before us
  // but their writes are not yet visible to us: make them so.
  memoryBarrier(commandBuffer_, kWorkStages | VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                kWrites | VK_ACCESS_MEMORY_WRITE_BIT, kWorkStages, kReadsWrites);
}

// The batch stops counting as recording (Context::deferDestroy tags with it no longer).
void CommandBatch::closeRecording() {
  if (ctx_ && ctx_->openBatches_ > 0) --ctx_->openBatches_;
}

CommandBatch::~CommandBatch() { release(); }

CommandBatch::CommandBatch(CommandBatch&& other) noexcept
    : ctx_(std::exchange(other.ctx_, nullptr)),
      commandBuffer_(std::exchange(other.commandBuffer_, VK_NULL_HANDLE)),
      queryPool_(std::exchange(other.queryPool_, VK_NULL_HANDLE)),
      maxPasses_(other.maxPasses_),
      passNames_(std::move(other.passNames_)),
      hasCommands_(other.hasCommands_),
      submission_(other.submission_),
      waited_(other.waited_),
      ownsCommandBuffer_(other.ownsCommandBuffer_) {}

CommandBatch& CommandBatch::operator=(CommandBatch&& other) noexcept {
  if (this != &other) {
    release();
    ctx_ = std::exchange(other.ctx_, nullptr);
    commandBuffer_ = std::exchange(other.commandBuffer_, VK_NULL_HANDLE);
    queryPool_ = std::exchange(other.queryPool_, VK_NULL_HANDLE);
    maxPasses_ = other.maxPasses_;
    passNames_ = std::move(other.passNames_);
    hasCommands_ = other.hasCommands_;
    submission_ = other.submission_;
    waited_ = other.waited_;
    ownsCommandBuffer_ = other.ownsCommandBuffer_;
  }
  return *this;
}

void CommandBatch::release() {
  if (!ctx_ || (!commandBuffer_ && !queryPool_)) return;
  if (!submitted()) closeRecording();
  // Never submitted: still in the recording state, which vkFreeCommandBuffers accepts. The
  // caller's command buffer is the caller's to free.
  ctx_->deferDestroy([device = ctx_->device(), pool = ctx_->commandPool(),
                      cb = ownsCommandBuffer_ ? commandBuffer_ : VK_NULL_HANDLE, qp = queryPool_] {
    if (cb) vkFreeCommandBuffers(device, pool, 1, &cb);
    if (qp) vkDestroyQueryPool(device, qp, nullptr);
  });
  commandBuffer_ = VK_NULL_HANDLE;
  queryPool_ = VK_NULL_HANDLE;
}

void CommandBatch::beforeCommand() {
  SDFSTREAM_GPU_CHECK(commandBuffer_ && !submitted(), "recording into a submitted batch");
  if (hasCommands_) memoryBarrier(commandBuffer_, kWorkStages, kWrites, kWorkStages, kReadsWrites);
  hasCommands_ = true;
}

void CommandBatch::dispatch(std::string_view name, const ComputePipeline& pipeline,
                            std::span<const Buffer* const> buffers, const void* push,
                            std::size_t pushBytes, glm::uvec3 threads) {
  recordPass(name, pipeline, buffers, push, pushBytes, [&](const std::string& who) {
    const glm::uvec3 size = pipeline.desc().workgroupSize;
    const glm::uvec3 count(groups(threads.x, size.x), groups(threads.y, size.y),
                           groups(threads.z, size.z));
    const std::uint32_t* limit = ctx_->properties().limits.maxComputeWorkGroupCount;
    SDFSTREAM_GPU_CHECK(count.x <= limit[0] && count.y <= limit[1] && count.z <= limit[2],
                        who +
                            "group count exceeds maxComputeWorkGroupCount (65535 on many "
                            "devices): spread the threads over y");
    vkCmdDispatch(commandBuffer_, count.x, count.y, count.z);
  });
}

void CommandBatch::dispatchIndirect(std::string_view name, const ComputePipeline& pipeline,
                                    std::span<const Buffer* const> buffers, const void* push,
                                    std::size_t pushBytes, const Buffer& args, std::size_t offset) {
  recordPass(name, pipeline, buffers, push, pushBytes, [&](const std::string& who) {
    SDFSTREAM_GPU_CHECK(args && offset % 4 == 0 && offset + 12 <= args.size(),
                        who + "indirect arguments outside their buffer");
    vkCmdDispatchIndirect(commandBuffer_, args.handle(), offset);
  });
}

void CommandBatch::recordPass(std::string_view name, const ComputePipeline& pipeline,
                              std::span<const Buffer* const> buffers, const void* push,
                              std::size_t pushBytes,
                              const std::function<void(const std::string&)>& issue) {
  const PipelineDesc& desc = pipeline.desc();
  const std::string who = "dispatch '" + std::string(name) + "' (" + pipeline.name() + "): ";
  SDFSTREAM_GPU_CHECK(pipeline, who + "empty pipeline");
  SDFSTREAM_GPU_CHECK(pushBytes == desc.pushConstantBytes && (push || pushBytes == 0),
                      who + "push-constant size differs from the pipeline's");
  SDFSTREAM_GPU_CHECK(buffers.size() == desc.storageBufferCount,
                      who + "buffer count differs from the pipeline's storageBufferCount");
  SDFSTREAM_GPU_CHECK(passNames_.size() < maxPasses_, who + "more passes than maxPasses");
  beforeCommand();

  const std::uint32_t query = openPass(name);
  vkCmdBindPipeline(commandBuffer_, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.handle());
  if (!buffers.empty()) {
    std::vector<VkDescriptorBufferInfo> infos(buffers.size());
    std::vector<VkWriteDescriptorSet> writes(buffers.size());
    for (std::size_t i = 0; i < buffers.size(); ++i) {
      SDFSTREAM_GPU_CHECK(buffers[i] && *buffers[i], who + "null or empty buffer");
      infos[i] = {buffers[i]->handle(), 0, VK_WHOLE_SIZE};
      writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      writes[i].dstBinding = static_cast<std::uint32_t>(i);
      writes[i].descriptorCount = 1;
      writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes[i].pBufferInfo = &infos[i];
    }
    ctx_->cmdPushDescriptorSet()(commandBuffer_, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.layout(),
                                 0, static_cast<std::uint32_t>(writes.size()), writes.data());
  }
  if (pushBytes)
    vkCmdPushConstants(commandBuffer_, pipeline.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                       static_cast<std::uint32_t>(pushBytes), push);
  issue(who);
  closePass(query);
}

std::uint32_t CommandBatch::openPass(std::string_view name) {
  const std::uint32_t query = 2 * static_cast<std::uint32_t>(passNames_.size());
  passNames_.emplace_back(name);
  if (ctx_->cmdBeginLabel()) {
    VkDebugUtilsLabelEXT label{VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT};
    label.pLabelName = passNames_.back().c_str();
    ctx_->cmdBeginLabel()(commandBuffer_, &label);
  }
  // BOTTOM_OF_PIPE for both: "when everything before has finished", so the interval covers this
  // pass (and the barrier wait before it), not work still draining from the previous pass.
  if (queryPool_)
    vkCmdWriteTimestamp(commandBuffer_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queryPool_, query);
  return query;
}

void CommandBatch::closePass(std::uint32_t query) {
  if (queryPool_)
    vkCmdWriteTimestamp(commandBuffer_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queryPool_,
                        query + 1);
  if (ctx_->cmdEndLabel()) ctx_->cmdEndLabel()(commandBuffer_);
}

void CommandBatch::record(std::string_view name,
                          const std::function<void(VkCommandBuffer)>& commands) {
  SDFSTREAM_GPU_CHECK(commandBuffer_ && !submitted(), "recording into a submitted batch");
  SDFSTREAM_GPU_CHECK(passNames_.size() < maxPasses_,
                      "record '" + std::string(name) + "': more passes than maxPasses");
  // Every earlier write, visible to every stage: the commands may read buffers from any stage
  // (vertex pulling, say), which the compute/transfer barrier of beforeCommand does not cover.
  if (hasCommands_)
    memoryBarrier(commandBuffer_, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT,
                  VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                  VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
  hasCommands_ = true;
  const std::uint32_t query = openPass(name);
  commands(commandBuffer_);
  closePass(query);
}

void CommandBatch::copy(const Buffer& src, Buffer& dst, std::size_t bytes, std::size_t srcOffset,
                        std::size_t dstOffset) {
  SDFSTREAM_GPU_CHECK(src && dst && src.handle() != dst.handle(),
                      "copy needs two distinct buffers");
  SDFSTREAM_GPU_CHECK(srcOffset <= src.size() && bytes <= src.size() - srcOffset &&
                          dstOffset <= dst.size() && bytes <= dst.size() - dstOffset,
                      "copy range outside a buffer");
  if (bytes == 0) return;  // vkCmdCopyBuffer forbids size 0
  beforeCommand();
  VkBufferCopy region{srcOffset, dstOffset, bytes};
  vkCmdCopyBuffer(commandBuffer_, src.handle(), dst.handle(), 1, &region);
}

void CommandBatch::copyRegions(const Buffer& src, Buffer& dst,
                               std::span<const VkBufferCopy> regions) {
  SDFSTREAM_GPU_CHECK(src && dst && src.handle() != dst.handle(),
                      "copyRegions needs two distinct buffers");
  std::vector<VkBufferCopy> used;
  used.reserve(regions.size());
  for (const VkBufferCopy& r : regions) {
    SDFSTREAM_GPU_CHECK(r.srcOffset <= src.size() && r.size <= src.size() - r.srcOffset &&
                            r.dstOffset <= dst.size() && r.size <= dst.size() - r.dstOffset,
                        "copyRegions range outside a buffer");
    if (r.size > 0) used.push_back(r);
  }
  if (used.empty()) return;
  beforeCommand();
  vkCmdCopyBuffer(commandBuffer_, src.handle(), dst.handle(), std::uint32_t(used.size()),
                  used.data());
}

void CommandBatch::fill(Buffer& dst, std::uint32_t value) {
  SDFSTREAM_GPU_CHECK(dst, "fill of an empty buffer");
  beforeCommand();
  vkCmdFillBuffer(commandBuffer_, dst.handle(), 0, VK_WHOLE_SIZE, value);
}

void CommandBatch::fill(Buffer& dst, std::uint32_t value, std::size_t offset, std::size_t bytes) {
  if (bytes == 0) return;
  SDFSTREAM_GPU_CHECK(dst, "fill of an empty buffer");
  SDFSTREAM_GPU_CHECK(offset % 4 == 0 && bytes % 4 == 0, "fill range not in 32-bit words");
  SDFSTREAM_GPU_CHECK(offset <= dst.size() && bytes <= dst.size() - offset,
                      "fill range outside the buffer");
  beforeCommand();
  vkCmdFillBuffer(commandBuffer_, dst.handle(), offset, bytes, value);
}

std::uint64_t CommandBatch::submit() {
  SDFSTREAM_GPU_CHECK(commandBuffer_ && !submitted(), "batch submitted twice");
  SDFSTREAM_GPU_CHECK(ownsCommandBuffer_,
                      "submit() of a batch recording into the caller's command buffer: finish()");
  closeRecording();
  // Make this batch's writes visible to the host once wait() returns (readback buffers).
  memoryBarrier(commandBuffer_, kWorkStages, kWrites, VK_PIPELINE_STAGE_HOST_BIT,
                VK_ACCESS_HOST_READ_BIT);
  SDFSTREAM_VK(vkEndCommandBuffer(commandBuffer_));
  submission_ = ctx_->submit(commandBuffer_);
  return submission_;
}

SubmitSignal CommandBatch::finish() {
  SDFSTREAM_GPU_CHECK(commandBuffer_ && !submitted(), "batch finished twice");
  SDFSTREAM_GPU_CHECK(!ownsCommandBuffer_, "finish() of an own batch: submit()");
  // The caller's later commands (its shading, any stage) and the host read what we wrote.
  memoryBarrier(commandBuffer_, kWorkStages, kWrites,
                VK_PIPELINE_STAGE_ALL_COMMANDS_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT | VK_ACCESS_HOST_READ_BIT);
  closeRecording();
  const SubmitSignal signal = ctx_->reserveSubmission();
  submission_ = signal.value;
  return signal;
}

bool CommandBatch::completed() const {
  return submitted() && (waited_ || ctx_->completedSubmission() >= submission_);
}

void CommandBatch::wait() {
  SDFSTREAM_GPU_CHECK(submitted(), "waiting for a batch that was not submitted");
  ctx_->wait(submission_);
  waited_ = true;
}

std::vector<PassTiming> CommandBatch::timings() const {
  SDFSTREAM_GPU_CHECK(completed(), "timings() before the batch completed");
  std::vector<PassTiming> out;
  out.reserve(passNames_.size());
  std::vector<std::uint64_t> ticks(2 * passNames_.size());
  if (queryPool_ && !ticks.empty())
    SDFSTREAM_VK(vkGetQueryPoolResults(
        ctx_->device(), queryPool_, 0, static_cast<std::uint32_t>(ticks.size()),
        ticks.size() * sizeof(std::uint64_t), ticks.data(), sizeof(std::uint64_t),
        VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  const std::uint32_t bits = ctx_->timestampValidBits();
  const std::uint64_t mask = bits >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << bits) - 1;
  for (std::size_t i = 0; i < passNames_.size(); ++i) {
    // Modular difference handles a counter that wrapped within its valid bits.
    const std::uint64_t delta = queryPool_ ? ((ticks[2 * i + 1] - ticks[2 * i]) & mask) : 0;
    out.push_back({passNames_[i], double(delta) * ctx_->timestampPeriodNs() * 1e-6});
  }
  return out;
}

}  // namespace sdfstream::gpu
