// The Vulkan instance, one physical device, its logical device and one compute queue, plus the
// submission timeline that drives deferred destruction (STYLE.md habit 5).
//
// Two ways to get one: create() makes its own instance and device (the CLI, the tests), adopt()
// wraps an engine's instance, device and queue without owning them (the engine destroys them,
// after this Context). Either way the Context owns its command pool, timeline semaphore and
// everything made from it.
//
// Thread safety: a Context and every object made from it (Buffer, ComputePipeline, CommandBatch)
// must be used from one thread at a time (external synchronization, as for a VkQueue). Only
// validationMessageCount() may be read concurrently.
//
// Lifetime: every Buffer, ComputePipeline and CommandBatch must be destroyed before its Context.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>

#include <vulkan/vulkan.h>

// beginBatch() returns a CommandBatch by value, so every caller needs the full type (and
// PassTiming) anyway.
#include "gpu/command_batch.h"
#include "gpu/deletion_queue.h"

namespace sdfstream::gpu {

struct ContextOptions {
  // "" = automatic (discrete > integrated > virtual > CPU), unless $SDFSTREAM_DEVICE is set, which
  // is then used as the request. Otherwise an enumeration index ("0") or a case-insensitive
  // substring of the device name ("llvmpipe", "rtx").
  std::string device;
  // Enables VK_LAYER_KHRONOS_validation and counts its messages. ORed with
  // $SDFSTREAM_VALIDATION=1. Context::create throws if requested but the layer is not installed.
  bool validation = false;
};

// An engine's Vulkan objects for Context::adopt. Vulkan cannot be asked what a VkDevice was
// created with, so the engine states it: the device extensions it enabled and its
// VkPhysicalDeviceVulkan12Features as passed to vkCreateDevice. requiredDeviceExtensions() and
// requiredVulkan12Features() say what to enable.
struct AdoptedDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  // The queue sdfstream submits its own (blocking) work to and whose family owns its buffers:
  // the engine submits recorded GI frames on a queue of this family.
  std::uint32_t queueFamily = 0;
  std::uint32_t queueIndex = 0;
  std::span<const char* const> enabledDeviceExtensions;
  VkPhysicalDeviceVulkan12Features enabledVulkan12Features{};  // only the flags are read
  // True when the instance was created with VK_EXT_debug_utils: with validation requested
  // (ContextOptions::validation or $SDFSTREAM_VALIDATION) the Context then counts the validation
  // layer's messages through its own messenger on the engine's instance.
  bool instanceHasDebugUtils = false;
};

// What the timeline semaphore of a recorded, caller-submitted command buffer must be signalled
// to (VkTimelineSemaphoreSubmitInfo): it tells the Context when that work has completed.
struct SubmitSignal {
  VkSemaphore semaphore = VK_NULL_HANDLE;
  std::uint64_t value = 0;
};

// Thrown by submit and wait once the device is lost (VK_ERROR_DEVICE_LOST): the GPU reset, hung
// or was removed. Not recoverable for this Context; the message is one line.
class DeviceLost : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Thrown by gpu::Buffer when the device has no memory left for it (VK_ERROR_OUT_OF_DEVICE_MEMORY,
// or, for tests, SDFSTREAM_INJECT_DEVICE_MEMORY_MIB=N: a device-local buffer that would take the
// Context's live buffers past N MiB).
// Callers that can make do with less catch it and ask for less (GpuStackScene::reserveAtlas).
class OutOfDeviceMemory : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Context {
 public:
  // Throws std::runtime_error with a one-line reason: no matching/suitable device, validation
  // layer missing, or a failed Vulkan call. Requirements: Vulkan 1.2, timeline semaphores,
  // VK_KHR_push_descriptor, a compute queue.
  static std::unique_ptr<Context> create(const ContextOptions& options = {});
  // Wraps an engine's device (see AdoptedDevice); options.device is ignored. Throws
  // std::runtime_error naming everything the device lacks (API version, extensions, features,
  // a compute-capable queue family).
  static std::unique_ptr<Context> adopt(const AdoptedDevice& device,
                                        const ContextOptions& options = {});
  // What adopt() needs enabled at vkCreateDevice: these extensions, and these Vulkan 1.2 features
  // (set to VK_TRUE), on a Vulkan 1.2 device with a compute queue.
  static std::span<const char* const> requiredDeviceExtensions();
  static VkPhysicalDeviceVulkan12Features requiredVulkan12Features();

  // True when the instance and device belong to the caller (adopt()).
  bool adopted() const { return adopted_; }

  // Waits for all submitted work (own and caller-submitted frames, through the timeline), runs
  // every deferred destruction, then destroys the device and instance if it made them.
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const std::string& deviceName() const { return deviceName_; }
  // True for a CPU implementation (lavapipe/llvmpipe, SwiftShader): callers may shrink workloads.
  bool isSoftware() const { return properties_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }
  // Bytes of the largest device-local memory heap: what one budget on the device can hope for.
  VkDeviceSize deviceLocalBytes() const;
  // Nanoseconds per timestamp tick (VkPhysicalDeviceLimits::timestampPeriod).
  double timestampPeriodNs() const { return properties_.limits.timestampPeriod; }
  // False when the compute queue has no timestamp support; CommandBatch timings are then 0 ms.
  bool timestampsSupported() const { return timestampValidBits_ != 0; }
  std::uint32_t timestampValidBits() const { return timestampValidBits_; }

  bool validationEnabled() const { return messenger_ != VK_NULL_HANDLE; }
  // Validation warnings and errors reported so far (each is also printed to stderr). 0 when
  // validation is off. Thread-safe.
  std::uint64_t validationMessageCount() const { return validationMessages_.load(); }
  // The same, summed over every Context of the process, including messages reported while a
  // Context was being destroyed (leaked objects): tests compare it before and after. Thread-safe.
  static std::uint64_t processValidationMessageCount();

  // A new command batch; see command_batch.h. `maxPasses` bounds the timed dispatches it records.
  CommandBatch beginBatch(std::uint32_t maxPasses = 64);
  // A batch recording into the caller's command buffer (begun, outside a render pass, from a
  // pool of queueFamily()); see CommandBatch::finish().
  CommandBatch recordInto(VkCommandBuffer commandBuffer, std::uint32_t maxPasses = 64);

  // --- Submission timeline. Submission n signals the timeline semaphore to value n. ---
  // Submits a recorded (ended) command buffer on the compute queue; returns its index.
  // Also frees deferred objects whose submission has completed.
  std::uint64_t submit(VkCommandBuffer commandBuffer);
  // Reserves the next submission index for a command buffer the caller records (CommandBatch
  // over an external command buffer) and submits itself, signalling the returned semaphore value.
  // Contract: that submission is made (on a queue of queueFamily()) before the next call that
  // submits on this Context, so the timeline's signals stay in increasing order.
  SubmitSignal reserveSubmission();
  std::uint64_t lastSubmission() const { return lastSubmission_; }
  std::uint64_t completedSubmission() const;
  // Blocks until submission `index` has completed, then frees what became free.
  void wait(std::uint64_t index);
  // Blocks until everything submitted has completed and frees every deferred object.
  void waitIdle();

  // True once a submit or a wait returned VK_ERROR_DEVICE_LOST. From then on every submit and
  // wait throws DeviceLost at once (a lost device signals nothing: waiting would never end) and
  // the destructor tears down without waiting. Test hook: SDFSTREAM_INJECT_DEVICE_LOST=N makes
  // the (N+1)-th submit of each Context fail as if the device were lost.
  bool deviceLost() const { return lost_; }

  // --- Counters (for tests and engines checking that a frame never blocks). ---
  // vkQueueSubmit calls made by this Context (not the caller's own submissions).
  std::uint64_t submitCount() const { return submitCount_; }
  // Times the CPU blocked on the GPU: wait() and waitIdle() calls, including those made by
  // blocking uploads, downloads and batches.
  std::uint64_t hostWaitCount() const { return hostWaitCount_; }
  // Bytes of the gpu::Buffers alive on this Context (all kinds): what a long run checks stays
  // flat. Thread-safe.
  std::uint64_t liveBufferBytes() const { return liveBufferBytes_.load(); }

  // --- Deferred destruction. ---
  // Queues `destroy` to run after the last submission made so far has completed, or, while
  // batches are being recorded, after theirs too (they may use the object). Owners call this from their destructors; the callback
  // must not throw. Not run immediately even if the GPU is idle: frees happen in submit(),
  // wait(), waitIdle(), collectGarbage() and ~Context.
  void deferDestroy(std::function<void()> destroy);
  // Frees deferred objects whose submission has completed, without waiting.
  void collectGarbage();
  std::size_t pendingDeletionCount() const { return deletions_.size(); }

  // --- Raw handles for advanced use (do not destroy them). ---
  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physicalDevice_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  std::uint32_t queueFamily() const { return queueFamily_; }
  VkCommandPool commandPool() const { return commandPool_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  const VkPhysicalDeviceMemoryProperties& memoryProperties() const { return memoryProperties_; }
  std::uint32_t maxPushDescriptors() const { return maxPushDescriptors_; }
  PFN_vkCmdPushDescriptorSetKHR cmdPushDescriptorSet() const { return cmdPushDescriptorSet_; }
  // Null when validation (and so VK_EXT_debug_utils) is off.
  // True when pipelines capture the driver's statistics and print them at creation
  // (SDFSTREAM_PIPELINE_STATS=1 on a device of the Context's own; gpu/pipeline_statistics.h).
  bool pipelineStatistics() const { return pipelineStatistics_; }
  PFN_vkCmdBeginDebugUtilsLabelEXT cmdBeginLabel() const { return cmdBeginLabel_; }
  PFN_vkCmdEndDebugUtilsLabelEXT cmdEndLabel() const { return cmdEndLabel_; }

 private:
  Context() = default;
  void createInstance(bool validation);
  VkDebugUtilsMessengerCreateInfoEXT messengerInfo();
  void createMessenger();
  void readDeviceProperties();
  void createOwnedObjects();
  void pickDevice(const std::string& request, const std::string& requestSource);
  void createDevice();
  static VKAPI_ATTR VkBool32 VKAPI_CALL onValidationMessage(
      VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT types,
      const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queueFamily_ = 0;
  std::uint32_t timestampValidBits_ = 0;
  VkCommandPool commandPool_ = VK_NULL_HANDLE;
  VkSemaphore timeline_ = VK_NULL_HANDLE;
  std::uint64_t lastSubmission_ = 0;
  std::uint64_t submitCount_ = 0;
  bool lost_ = false;
  std::uint64_t injectLossAfterSubmits_ = 0;  // 0: never (SDFSTREAM_INJECT_DEVICE_LOST)
  [[noreturn]] void deviceLostError(const char* call);
  std::uint64_t hostWaitCount_ = 0;
  bool adopted_ = false;
  bool pipelineStatistics_ = false;
  std::uint64_t openBatches_ = 0;  // CommandBatches recording, not yet submitted or released
  std::uint64_t deferTag_ = 0;     // the submission the newest deferred destruction waits for
  friend class CommandBatch;

  std::string deviceName_;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memoryProperties_{};
  std::uint32_t maxPushDescriptors_ = 0;
  PFN_vkCmdPushDescriptorSetKHR cmdPushDescriptorSet_ = nullptr;
  PFN_vkCmdBeginDebugUtilsLabelEXT cmdBeginLabel_ = nullptr;
  PFN_vkCmdEndDebugUtilsLabelEXT cmdEndLabel_ = nullptr;

  std::atomic<std::uint64_t> validationMessages_{0};
  std::atomic<std::uint64_t> liveBufferBytes_{0};  // kept by gpu::Buffer
  friend class Buffer;
  DeletionQueue deletions_;
};

}  // namespace sdfstream::gpu
