// Context, part 2: device choice, logical device, and the submission timeline.
#include "gpu/context.h"

#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "gpu/check.h"
#include "gpu/command_batch.h"
#include "gpu/device_select.h"

namespace sdfstream::gpu {
namespace {

bool envFlag(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::strcmp(v, "0") != 0;
}

bool hasDeviceExtension(VkPhysicalDevice device, const char* name) {
  std::uint32_t count = 0;
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
  for (const auto& e : extensions)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

// The family to submit compute work to: the first with compute, preferring one with timestamps.
// nullopt-like UINT32_MAX when there is none.
std::uint32_t findComputeFamily(VkPhysicalDevice device, std::uint32_t* timestampBits) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  std::uint32_t chosen = UINT32_MAX;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (!(families[i].queueFlags & VK_QUEUE_COMPUTE_BIT)) continue;
    if (chosen == UINT32_MAX ||
        (families[chosen].timestampValidBits == 0 && families[i].timestampValidBits != 0))
      chosen = i;
  }
  if (chosen != UINT32_MAX && timestampBits) *timestampBits = families[chosen].timestampValidBits;
  return chosen;
}

std::string unsuitableReason(VkPhysicalDevice device, const VkPhysicalDeviceProperties& props) {
  if (props.apiVersion < VK_API_VERSION_1_2) return "needs Vulkan 1.2";
  if (!hasDeviceExtension(device, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME))
    return "lacks " VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME;
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  f2.pNext = &f12;
  vkGetPhysicalDeviceFeatures2(device, &f2);
  if (!f12.timelineSemaphore) return "lacks timeline semaphores";
  if (findComputeFamily(device, nullptr) == UINT32_MAX) return "has no compute queue";
  return {};
}

}  // namespace

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

void Context::pickDevice(const std::string& request, const std::string& requestSource) {
  std::uint32_t count = 0;
  SDFSTREAM_VK(vkEnumeratePhysicalDevices(instance_, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  SDFSTREAM_VK(vkEnumeratePhysicalDevices(instance_, &count, devices.data()));
  std::vector<DeviceCandidate> candidates;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    candidates.push_back({p.deviceName, p.deviceType, unsuitableReason(d, p)});
  }
  physicalDevice_ = devices[selectDevice(candidates, request, requestSource)];

  VkPhysicalDevicePushDescriptorPropertiesKHR push{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PUSH_DESCRIPTOR_PROPERTIES_KHR};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  p2.pNext = &push;
  vkGetPhysicalDeviceProperties2(physicalDevice_, &p2);
  properties_ = p2.properties;
  maxPushDescriptors_ = push.maxPushDescriptors;
  deviceName_ = properties_.deviceName;
  vkGetPhysicalDeviceMemoryProperties(physicalDevice_, &memoryProperties_);
  queueFamily_ = findComputeFamily(physicalDevice_, &timestampValidBits_);
}

void Context::createDevice() {
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queueInfo.queueFamilyIndex = queueFamily_;
  queueInfo.queueCount = 1;
  queueInfo.pQueuePriorities = &priority;

  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  f12.timelineSemaphore = VK_TRUE;
  const char* extensions[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};

  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.pNext = &f12;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queueInfo;
  info.enabledExtensionCount = 1;
  info.ppEnabledExtensionNames = extensions;
  SDFSTREAM_VK(vkCreateDevice(physicalDevice_, &info, nullptr, &device_));
  vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);

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
  if (device_) {
    // Not waitIdle(): a destructor must not throw, and a lost device must still be torn down.
    vkDeviceWaitIdle(device_);
    deletions_.runAll();
    if (timeline_) vkDestroySemaphore(device_, timeline_, nullptr);
    if (commandPool_) vkDestroyCommandPool(device_, commandPool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

CommandBatch Context::beginBatch(std::uint32_t maxPasses) { return CommandBatch(*this, maxPasses); }

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
  SDFSTREAM_VK(vkQueueSubmit(queue_, 1, &info, VK_NULL_HANDLE));
  lastSubmission_ = index;
  collectGarbage();
  return index;
}

std::uint64_t Context::completedSubmission() const {
  std::uint64_t value = 0;
  SDFSTREAM_VK(vkGetSemaphoreCounterValue(device_, timeline_, &value));
  return value;
}

void Context::wait(std::uint64_t index) {
  SDFSTREAM_GPU_CHECK(index <= lastSubmission_, "waiting for a submission that was never made");
  VkSemaphoreWaitInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
  info.semaphoreCount = 1;
  info.pSemaphores = &timeline_;
  info.pValues = &index;
  SDFSTREAM_VK(vkWaitSemaphores(device_, &info, UINT64_MAX));
  collectGarbage();
}

void Context::waitIdle() {
  wait(lastSubmission_);
  // Everything queued so far belongs to submissions <= lastSubmission_, now complete.
  deletions_.runAll();
}

void Context::deferDestroy(std::function<void()> destroy) {
  deletions_.push(lastSubmission_, std::move(destroy));
}

void Context::collectGarbage() { deletions_.collect(completedSubmission()); }

}  // namespace sdfstream::gpu
