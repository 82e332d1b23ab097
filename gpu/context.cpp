// Context, part 2: device choice or adoption, the logical device, and the submission timeline.
#include "gpu/context.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "gpu/check.h"
#include "gpu/command_batch.h"
#include "gpu/device_requirements.h"
#include "gpu/device_select.h"
#include "gpu/pipeline_statistics.h"

namespace sdfstream::gpu {
namespace {

bool envFlag(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::strcmp(v, "0") != 0;
}

std::string joined(const std::vector<std::string>& parts) {
  std::string out;
  for (const std::string& p : parts) out += (out.empty() ? "" : "; ") + p;
  return out;
}

}  // namespace

std::span<const char* const> Context::requiredDeviceExtensions() { return requiredExtensions(); }
VkPhysicalDeviceVulkan12Features Context::requiredVulkan12Features() {
  return requiredFeatures12();
}

std::unique_ptr<Context> Context::create(const ContextOptions& options) {
  std::unique_ptr<Context> ctx(new Context());  // private constructor: no make_unique
  ctx->createInstance(options.validation || envFlag("SDFSTREAM_VALIDATION"));
  std::string request = options.device, source = "--device";
  if (request.empty())
    if (const char* env = std::getenv("SDFSTREAM_DEVICE"); env && *env) {
      request = env;
      source = "SDFSTREAM_DEVICE";
    }
  ctx->pickDevice(request, source);
  ctx->createDevice();
  return ctx;
}

std::unique_ptr<Context> Context::adopt(const AdoptedDevice& engine, const ContextOptions& options) {
  if (!engine.instance || !engine.physicalDevice || !engine.device)
    throw std::runtime_error("sdfstream: Context::adopt needs the engine's VkInstance, "
                             "VkPhysicalDevice and VkDevice (one of them is null)");
  const EnabledDeviceState enabled{engine.enabledDeviceExtensions,
                                   &engine.enabledVulkan12Features};
  std::vector<std::string> missing = missingRequirements(engine.physicalDevice, &enabled);
  const VkQueueFamilyProperties family =
      queueFamilyProperties(engine.physicalDevice, engine.queueFamily);
  if (!(family.queueFlags & VK_QUEUE_COMPUTE_BIT))
    missing.push_back("compute on queue family " + std::to_string(engine.queueFamily));
  else if (engine.queueIndex >= family.queueCount)
    missing.push_back("queue " + std::to_string(engine.queueIndex) + " of family " +
                      std::to_string(engine.queueFamily) + " (it has " +
                      std::to_string(family.queueCount) + ")");
  if (!missing.empty())
    throw std::runtime_error("sdfstream cannot use the engine's Vulkan device: it lacks " +
                             joined(missing) +
                             " (needs Vulkan 1.2, Context::requiredDeviceExtensions() and "
                             "Context::requiredVulkan12Features() enabled at vkCreateDevice)");

  std::unique_ptr<Context> ctx(new Context());
  ctx->adopted_ = true;
  ctx->instance_ = engine.instance;
  ctx->physicalDevice_ = engine.physicalDevice;
  ctx->device_ = engine.device;
  ctx->queueFamily_ = engine.queueFamily;
  ctx->timestampValidBits_ = family.timestampValidBits;
  ctx->readDeviceProperties();
  if ((options.validation || envFlag("SDFSTREAM_VALIDATION")) && engine.instanceHasDebugUtils)
    ctx->createMessenger();
  vkGetDeviceQueue(ctx->device_, engine.queueFamily, engine.queueIndex, &ctx->queue_);
  ctx->createOwnedObjects();
  return ctx;
}

void Context::pickDevice(const std::string& request, const std::string& requestSource) {
  std::uint32_t count = 0;
  SDFSTREAM_VK(vkEnumeratePhysicalDevices(instance_, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  SDFSTREAM_VK(vkEnumeratePhysicalDevices(instance_, &count, devices.data()));
  std::vector<DeviceCandidate> candidates;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    const std::vector<std::string> missing = missingRequirements(d);
    candidates.push_back({p.deviceName, p.deviceType, missing.empty() ? "" : "lacks " + joined(missing)});
  }
  physicalDevice_ = devices[selectDevice(candidates, request, requestSource)];
  readDeviceProperties();
  queueFamily_ = findComputeFamily(physicalDevice_, &timestampValidBits_);
}

void Context::readDeviceProperties() {
  VkPhysicalDevicePushDescriptorPropertiesKHR push{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PUSH_DESCRIPTOR_PROPERTIES_KHR};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  p2.pNext = &push;
  vkGetPhysicalDeviceProperties2(physicalDevice_, &p2);
  properties_ = p2.properties;
  maxPushDescriptors_ = push.maxPushDescriptors;
  deviceName_ = properties_.deviceName;
  vkGetPhysicalDeviceMemoryProperties(physicalDevice_, &memoryProperties_);
}

void Context::createDevice() {
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queueInfo.queueFamilyIndex = queueFamily_;
  queueInfo.queueCount = 1;
  queueInfo.pQueuePriorities = &priority;

  VkPhysicalDeviceVulkan12Features f12 = requiredFeatures12();
  std::vector<const char*> extensions(requiredExtensions().begin(), requiredExtensions().end());
  // The compiler's resource report, on request only: capturing it may cost pipeline-cache hits.
  VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR statistics{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
  pipelineStatistics_ = envFlag("SDFSTREAM_PIPELINE_STATS") &&
                        supportsExtension(physicalDevice_, kPipelineStatisticsExtension);
  if (pipelineStatistics_) {
    extensions.push_back(kPipelineStatisticsExtension);
    statistics.pipelineExecutableInfo = VK_TRUE;
    f12.pNext = &statistics;
  }

  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.pNext = &f12;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queueInfo;
  info.enabledExtensionCount = std::uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  SDFSTREAM_VK(vkCreateDevice(physicalDevice_, &info, nullptr, &device_));
  vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);
  createOwnedObjects();
}

// What the Context owns on any device, its own or adopted.
void Context::createOwnedObjects() {
  if (const char* v = std::getenv("SDFSTREAM_INJECT_DEVICE_LOST"); v && *v)
    injectLossAfterSubmits_ = std::strtoull(v, nullptr, 10);
  cmdPushDescriptorSet_ = reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(
      vkGetDeviceProcAddr(device_, "vkCmdPushDescriptorSetKHR"));
  SDFSTREAM_GPU_CHECK(cmdPushDescriptorSet_ != nullptr, "vkCmdPushDescriptorSetKHR not loadable");

  VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  poolInfo.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  poolInfo.queueFamilyIndex = queueFamily_;
  SDFSTREAM_VK(vkCreateCommandPool(device_, &poolInfo, nullptr, &commandPool_));

  VkSemaphoreTypeCreateInfo typeInfo{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
  typeInfo.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
  typeInfo.initialValue = 0;
  VkSemaphoreCreateInfo semInfo{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  semInfo.pNext = &typeInfo;
  SDFSTREAM_VK(vkCreateSemaphore(device_, &semInfo, nullptr, &timeline_));
}

Context::~Context() {
  if (device_ && lost_) {
    // Nothing the lost device was given will complete: free without waiting.
    deletions_.runAll();
    if (timeline_) vkDestroySemaphore(device_, timeline_, nullptr);
    if (commandPool_) vkDestroyCommandPool(device_, commandPool_, nullptr);
    if (!adopted_) vkDestroyDevice(device_, nullptr);
  } else if (device_) {
    // Not waitIdle(): a destructor must not throw, and a lost device must still be torn down.
    // An adopted device is the engine's: wait for our own timeline only, not for its work.
    if (adopted_ && timeline_) {
      VkSemaphoreWaitInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
      info.semaphoreCount = 1;
      info.pSemaphores = &timeline_;
      info.pValues = &lastSubmission_;
      vkWaitSemaphores(device_, &info, UINT64_MAX);
    } else {
      vkDeviceWaitIdle(device_);
    }
    deletions_.runAll();
    if (timeline_) vkDestroySemaphore(device_, timeline_, nullptr);
    if (commandPool_) vkDestroyCommandPool(device_, commandPool_, nullptr);
    if (!adopted_) vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_ && !adopted_) vkDestroyInstance(instance_, nullptr);
}

CommandBatch Context::beginBatch(std::uint32_t maxPasses) { return CommandBatch(*this, maxPasses); }
CommandBatch Context::recordInto(VkCommandBuffer commandBuffer, std::uint32_t maxPasses) {
  return CommandBatch(*this, commandBuffer, maxPasses);
}

std::uint64_t Context::submit(VkCommandBuffer commandBuffer) {
  const std::uint64_t index = lastSubmission_ + 1;
  VkTimelineSemaphoreSubmitInfo timelineInfo{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  timelineInfo.signalSemaphoreValueCount = 1;
  timelineInfo.pSignalSemaphoreValues = &index;
  VkSubmitInfo info{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  info.pNext = &timelineInfo;
  info.commandBufferCount = 1;
  info.pCommandBuffers = &commandBuffer;
  info.signalSemaphoreCount = 1;
  info.pSignalSemaphores = &timeline_;
  if (lost_) deviceLostError("vkQueueSubmit");
  if (injectLossAfterSubmits_ && submitCount_ >= injectLossAfterSubmits_) {
    lost_ = true;
    deviceLostError("vkQueueSubmit (injected by SDFSTREAM_INJECT_DEVICE_LOST)");
  }
  const VkResult submitted = vkQueueSubmit(queue_, 1, &info, VK_NULL_HANDLE);
  if (submitted == VK_ERROR_DEVICE_LOST) {
    lost_ = true;
    deviceLostError("vkQueueSubmit");
  }
  SDFSTREAM_VK(submitted);
  ++submitCount_;
  lastSubmission_ = index;
  collectGarbage();
  return index;
}

SubmitSignal Context::reserveSubmission() {
  lastSubmission_ += 1;
  return {timeline_, lastSubmission_};
}

VkDeviceSize Context::deviceLocalBytes() const {
  VkDeviceSize largest = 0;
  for (std::uint32_t i = 0; i < memoryProperties_.memoryHeapCount; ++i)
    if (memoryProperties_.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      largest = std::max(largest, memoryProperties_.memoryHeaps[i].size);
  return largest;
}

std::uint64_t Context::completedSubmission() const {
  std::uint64_t value = 0;
  if (lost_) return value;  // a lost device completes nothing more
  SDFSTREAM_VK(vkGetSemaphoreCounterValue(device_, timeline_, &value));
  return value;
}

void Context::wait(std::uint64_t index) {
  SDFSTREAM_GPU_CHECK(index <= lastSubmission_, "waiting for a submission that was never made");
  ++hostWaitCount_;
  VkSemaphoreWaitInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
  info.semaphoreCount = 1;
  info.pSemaphores = &timeline_;
  info.pValues = &index;
  if (lost_) deviceLostError("vkWaitSemaphores");
  const VkResult waited = vkWaitSemaphores(device_, &info, UINT64_MAX);
  if (waited == VK_ERROR_DEVICE_LOST) {
    lost_ = true;
    deviceLostError("vkWaitSemaphores");
  }
  SDFSTREAM_VK(waited);
  collectGarbage();
}

void Context::deviceLostError(const char* call) {
  throw DeviceLost("the GPU (" + deviceName_ + ") was lost: " + call +
                   " returned VK_ERROR_DEVICE_LOST (driver reset, hang or removal); "
                   "nothing more can run on it");
}

void Context::waitIdle() {
  wait(lastSubmission_);
  // With no batch recording, everything queued belongs to completed submissions.
  if (openBatches_ == 0) deletions_.runAll();
}

void Context::deferDestroy(std::function<void()> destroy) {
  // A batch still recording may use the object too; it becomes one of the next submissions.
  // Never earlier than an earlier tag (a batch abandoned unsubmitted lowers the count): freeing
  // later is always safe, and the queue stays sorted.
  deferTag_ = std::max(deferTag_, lastSubmission_ + openBatches_);
  deletions_.push(deferTag_, std::move(destroy));
}

void Context::collectGarbage() { deletions_.collect(completedSubmission()); }

}  // namespace sdfstream::gpu
