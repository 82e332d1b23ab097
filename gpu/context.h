// The Vulkan instance, one physical device, its logical device and one compute queue, plus the
// submission timeline that drives deferred destruction (STYLE.md habit 5).
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

class Context {
 public:
  // Throws std::runtime_error with a one-line reason: no matching/suitable device, validation
  // layer missing, or a failed Vulkan call. Requirements: Vulkan 1.2, timeline semaphores,
  // VK_KHR_push_descriptor, a compute queue.
  static std::unique_ptr<Context> create(const ContextOptions& options = {});

  // Waits for all submitted work, runs every deferred destruction, then destroys the device.
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const std::string& deviceName() const { return deviceName_; }
  // True for a CPU implementation (lavapipe/llvmpipe, SwiftShader): callers may shrink workloads.
  bool isSoftware() const { return properties_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }
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

  // --- Submission timeline. Submission n signals the timeline semaphore to value n. ---
  // Submits a recorded (ended) command buffer on the compute queue; returns its index.
  // Also frees deferred objects whose submission has completed.
  std::uint64_t submit(VkCommandBuffer commandBuffer);
  std::uint64_t lastSubmission() const { return lastSubmission_; }
  std::uint64_t completedSubmission() const;
  // Blocks until submission `index` has completed, then frees what became free.
  void wait(std::uint64_t index);
  // Blocks until everything submitted has completed and frees every deferred object.
  void waitIdle();

  // --- Deferred destruction. ---
  // Queues `destroy` to run after the last submission made so far has completed (so any work
  // that may use the object has finished). Owners call this from their destructors; the callback
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
  PFN_vkCmdBeginDebugUtilsLabelEXT cmdBeginLabel() const { return cmdBeginLabel_; }
  PFN_vkCmdEndDebugUtilsLabelEXT cmdEndLabel() const { return cmdEndLabel_; }

 private:
  Context() = default;
  void createInstance(bool validation);
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

  std::string deviceName_;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memoryProperties_{};
  std::uint32_t maxPushDescriptors_ = 0;
  PFN_vkCmdPushDescriptorSetKHR cmdPushDescriptorSet_ = nullptr;
  PFN_vkCmdBeginDebugUtilsLabelEXT cmdBeginLabel_ = nullptr;
  PFN_vkCmdEndDebugUtilsLabelEXT cmdEndLabel_ = nullptr;

  std::atomic<std::uint64_t> validationMessages_{0};
  DeletionQueue deletions_;
};

}  // namespace sdfstream::gpu
