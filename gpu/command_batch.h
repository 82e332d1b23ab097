// The one way to record GPU work (STYLE.md habit 3): every dispatch goes through dispatch(),
// which checks the push-constant size against the pipeline, rounds group counts up from thread
// counts, binds the buffers as push descriptors, puts a barrier between dependent commands and
// brackets the pass with GPU timestamps.
//
// Usage:
//   CommandBatch batch = ctx.beginBatch();
//   batch.dispatch("saxpy", pipeline, {&x, &y}, &push, sizeof push, {n, 1, 1});
//   batch.submitAndWait();
//   for (const PassTiming& t : batch.timings()) ...
//
// Synchronization contract: commands in a batch run in recording order, each seeing the
// previous ones' writes (a full compute/transfer barrier separates every pair -- simple and
// correct; passes that could overlap are rare in this project). A batch also sees the writes of
// every earlier submission, and after wait() the host sees its writes to mapped buffers.
// Buffers and pipelines used by a batch must stay alive until it is submitted; after that they
// may be destroyed at any time (deferred destruction keeps them until the batch has finished).
//
// Two modes. An own batch (Context::beginBatch) allocates its command buffer and is submitted by
// submit(). A recording batch (Context::recordInto) records into the caller's command buffer;
// finish() closes it with a barrier making its writes visible to the caller's later commands
// (any stage) and to the host, and returns the timeline signal the caller's vkQueueSubmit must
// carry. Either way the batch's timestamps are read once its submission has completed
// (completed(), never blocking) or after wait().
//
// Move-only. Thread safety: as for the Context.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <vulkan/vulkan.h>
#include <glm/vec3.hpp>

namespace sdfstream::gpu {

class Buffer;
class ComputePipeline;
class Context;
struct SubmitSignal;

struct PassTiming {
  std::string name;     // as given to dispatch()
  double milliseconds;  // GPU time between the timestamps around the pass; >= 0; 0 when the
                        // queue has no timestamps (Context::timestampsSupported())
};

// Threads of a 64-wide 1D pass spread over rows of 64 x 16384, so a launch of any size stays
// within the 65535 workgroups per axis Vulkan guarantees. The shader's linear index is then
// gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64.
inline glm::uvec3 spreadOverRows(std::uint32_t threads) {
  constexpr std::uint32_t kRow = 64u * 16384u;
  if (threads <= kRow) return {threads, 1, 1};
  return {kRow, (threads + kRow - 1) / kRow, 1};
}

class CommandBatch {
 public:
  ~CommandBatch();
  CommandBatch(CommandBatch&& other) noexcept;
  CommandBatch& operator=(CommandBatch&& other) noexcept;
  CommandBatch(const CommandBatch&) = delete;
  CommandBatch& operator=(const CommandBatch&) = delete;

  // Records one compute pass over `threads` invocations (group counts = ceil(threads /
  // workgroupSize); a zero component records an empty dispatch). `buffers[i]` is bound to
  // binding i of set 0. Checked (abort): pushBytes == pipeline.desc().pushConstantBytes,
  // buffers.size() == storageBufferCount, at most maxPasses passes, batch not yet submitted,
  // group counts within maxComputeWorkGroupCount (only 65535 guaranteed per axis: 64-wide
  // groups cover 4,194,240 threads in x; spread larger launches over y).
  void dispatch(std::string_view name, const ComputePipeline& pipeline,
                std::span<const Buffer* const> buffers, const void* push, std::size_t pushBytes,
                glm::uvec3 threads);
  void dispatch(std::string_view name, const ComputePipeline& pipeline,
                std::initializer_list<const Buffer*> buffers, const void* push,
                std::size_t pushBytes, glm::uvec3 threads) {
    dispatch(name, pipeline, std::span<const Buffer* const>(buffers.begin(), buffers.size()), push,
             pushBytes, threads);
  }

  // As dispatch(), with the group counts (three uints) read by the GPU from `args` at `offset`
  // when the pass runs: an earlier pass of the batch can size this one (e.g. by a list length),
  // so no thread is launched for work that does not exist. `args` must come from this library
  // (every Buffer may serve as indirect arguments).
  void dispatchIndirect(std::string_view name, const ComputePipeline& pipeline,
                        std::span<const Buffer* const> buffers, const void* push,
                        std::size_t pushBytes, const Buffer& args, std::size_t offset);

  // Records commands the batch has no helper for (a render pass, image copies) as one timed
  // pass: a full memory barrier (every stage) separates them from the batch's earlier commands,
  // and `commands` gets the batch's command buffer. Contract: the commands leave their results
  // written by compute or transfer stages (add your own barrier inside otherwise, e.g. after a
  // render pass before copying its images out), as the batch's next barrier covers those only.
  // Counts against maxPasses like a dispatch.
  void record(std::string_view name, const std::function<void(VkCommandBuffer)>& commands);
  // Copies `bytes` (multiple of 4 not required) from src+srcOffset to dst+dstOffset. Checked
  // (abort): both ranges inside their buffers; the two buffers differ.
  void copy(const Buffer& src, Buffer& dst, std::size_t bytes, std::size_t srcOffset = 0,
            std::size_t dstOffset = 0);
  // Several copies from src to dst in one command (one barrier before it, none between them):
  // the regions' destination ranges must not overlap. Checked like copy(); empty regions skipped.
  void copyRegions(const Buffer& src, Buffer& dst, std::span<const VkBufferCopy> regions);
  // Sets every 32-bit word of `dst` to `value`.
  void fill(Buffer& dst, std::uint32_t value);
  // Sets the 32-bit words of dst's [offset, offset + bytes) to `value`. Checked (abort): the
  // range lies inside the buffer; offset and bytes are multiples of 4. Nothing when bytes is 0.
  void fill(Buffer& dst, std::uint32_t value, std::size_t offset, std::size_t bytes);

  // Ends recording and submits; returns the submission index (Context::wait). Once only; own
  // batches only.
  std::uint64_t submit();
  // Closes a recording batch (recordInto) without ending the caller's command buffer; returns
  // what the caller's submission of it must signal. Once only; recording batches only.
  SubmitSignal finish();
  bool recordsIntoCaller() const { return !ownsCommandBuffer_; }
  // Submitted (or finished) and completed on the GPU; never blocks.
  bool completed() const;
  std::uint64_t submission() const { return submission_; }
  // Blocks until this batch has finished. Precondition: submitted.
  void wait();
  void submitAndWait() {
    submit();
    wait();
  }
  bool submitted() const { return submission_ != 0; }

  // One entry per dispatch, in recording order. Precondition (checked): wait() has returned or
  // completed() is true.
  std::vector<PassTiming> timings() const;

 private:
  friend class Context;
  CommandBatch(Context& ctx, std::uint32_t maxPasses);
  CommandBatch(Context& ctx, VkCommandBuffer callerCommandBuffer, std::uint32_t maxPasses);
  void createQueryPool();
  void beginRecording();
  void closeRecording();
  void beforeCommand();
  // Binds, pushes, times and labels one pass; `issue` records the dispatch command itself.
  void recordPass(std::string_view name, const ComputePipeline& pipeline,
                  std::span<const Buffer* const> buffers, const void* push, std::size_t pushBytes,
                  const std::function<void(const std::string&)>& issue);
  // Names, labels and opens the timestamps of one pass (returns its first query), and closes it.
  std::uint32_t openPass(std::string_view name);
  void closePass(std::uint32_t query);
  void release();

  Context* ctx_ = nullptr;
  VkCommandBuffer commandBuffer_ = VK_NULL_HANDLE;
  VkQueryPool queryPool_ = VK_NULL_HANDLE;  // 2 timestamps per pass; null when maxPasses == 0
  std::uint32_t maxPasses_ = 0;
  std::vector<std::string> passNames_;
  bool hasCommands_ = false;  // a barrier is needed before the next command
  std::uint64_t submission_ = 0;
  bool waited_ = false;
  bool ownsCommandBuffer_ = true;
};

}  // namespace sdfstream::gpu
