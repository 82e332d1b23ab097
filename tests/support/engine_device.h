// A stand-in for a game engine's Vulkan set-up, for the tests that hand a device to sdfstream:
// its own instance (with the validation layer and VK_EXT_debug_utils, so the adopted Context
// counts validation messages), the first physical device, a device created with what
// gpu::Context::requiredDeviceExtensions()/requiredVulkan12Features() ask for, one compute
// queue, and per frame in flight a command buffer and a fence of its own. It destroys everything
// itself, after the Context that adopted it.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <vulkan/vulkan.h>

#include "gpu/context.h"

namespace sdfstream::test {

class EngineDevice {
 public:
  // `withExtensions` false leaves out the device extensions sdfstream needs (to test the error).
  explicit EngineDevice(std::uint32_t framesInFlight = 2, bool withExtensions = true) {
    createInstance();
    std::uint32_t count = 1;
    vkEnumeratePhysicalDevices(instance, &count, &physicalDevice);
    if (count == 0) throw std::runtime_error("no Vulkan device");
    queueFamily = computeFamily();
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    q.queueFamilyIndex = queueFamily;
    q.queueCount = 1;
    q.pQueuePriorities = &priority;
    features12 = gpu::Context::requiredVulkan12Features();
    if (withExtensions)
      for (const char* e : gpu::Context::requiredDeviceExtensions()) extensions.push_back(e);
    VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    info.pNext = &features12;
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &q;
    info.enabledExtensionCount = std::uint32_t(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    check(vkCreateDevice(physicalDevice, &info, nullptr, &device), "vkCreateDevice");
    vkGetDeviceQueue(device, queueFamily, 0, &queue);
    createFrames(framesInFlight);
  }
  ~EngineDevice() {
    if (device) {
      vkDeviceWaitIdle(device);
      for (VkFence f : fences) vkDestroyFence(device, f, nullptr);
      vkDestroyCommandPool(device, pool, nullptr);
      vkDestroyDevice(device, nullptr);
    }
    vkDestroyInstance(instance, nullptr);
  }
  EngineDevice(const EngineDevice&) = delete;
  EngineDevice& operator=(const EngineDevice&) = delete;

  gpu::AdoptedDevice adopted() const {
    gpu::AdoptedDevice a;
    a.instance = instance;
    a.physicalDevice = physicalDevice;
    a.device = device;
    a.queueFamily = queueFamily;
    a.queueIndex = 0;
    a.enabledDeviceExtensions = extensions;
    a.enabledVulkan12Features = features12;
    a.instanceHasDebugUtils = true;
    return a;
  }

  // The engine's frame loop: waits for its own fence of the slot, resets and begins the slot's
  // command buffer.
  VkCommandBuffer beginFrame(std::uint64_t frame) {
    slot = std::uint32_t(frame % commandBuffers.size());
    vkWaitForFences(device, 1, &fences[slot], VK_TRUE, UINT64_MAX);
    // Also sdfstream's timeline value of that frame: a fence may precede it by a moment.
    if (slotSignals[slot].semaphore) {
      VkSemaphoreWaitInfo wi{};
      wi.sType = VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO;
      wi.semaphoreCount = 1;
      wi.pSemaphores = &slotSignals[slot].semaphore;
      wi.pValues = &slotSignals[slot].value;
      vkWaitSemaphores(device, &wi, UINT64_MAX);
    }
    vkResetFences(device, 1, &fences[slot]);
    vkResetCommandBuffer(commandBuffers[slot], 0);
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vkBeginCommandBuffer(commandBuffers[slot], &begin);
    return commandBuffers[slot];
  }
  // Ends and submits the slot's command buffer once, signalling sdfstream's timeline value and
  // the engine's fence.
  void submitFrame(const gpu::SubmitSignal& signal) {
    VkCommandBuffer cb = commandBuffers[slot];
    vkEndCommandBuffer(cb);
    VkTimelineSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
    timeline.signalSemaphoreValueCount = 1;
    timeline.pSignalSemaphoreValues = &signal.value;
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.pNext = &timeline;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cb;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &signal.semaphore;
    check(vkQueueSubmit(queue, 1, &submit, fences[slot]), "vkQueueSubmit");
    slotSignals[slot] = signal;
    ++submissions;
  }

  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  std::uint32_t queueFamily = 0;
  std::vector<const char*> extensions;
  VkPhysicalDeviceVulkan12Features features12{};
  VkCommandPool pool = VK_NULL_HANDLE;
  std::vector<VkCommandBuffer> commandBuffers;
  std::vector<VkFence> fences;
  std::vector<gpu::SubmitSignal> slotSignals;  // the last frame submitted from each slot
  std::uint32_t slot = 0;
  std::uint64_t submissions = 0;  // the engine's own vkQueueSubmit calls

 private:
  static void check(VkResult r, const char* what) {
    if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed");
  }
  void createInstance() {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "engine";
    app.apiVersion = VK_API_VERSION_1_2;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const char* debugUtils = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pApplicationInfo = &app;
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = &layer;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = &debugUtils;
    check(vkCreateInstance(&info, nullptr, &instance), "vkCreateInstance (validation layer)");
  }
  std::uint32_t computeFamily() const {
    std::uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &n, families.data());
    for (std::uint32_t i = 0; i < n; ++i)
      if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) return i;
    throw std::runtime_error("no compute queue");
  }
  void createFrames(std::uint32_t framesInFlight) {
    VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    poolInfo.queueFamilyIndex = queueFamily;
    check(vkCreateCommandPool(device, &poolInfo, nullptr, &pool), "vkCreateCommandPool");
    commandBuffers.resize(framesInFlight);
    slotSignals.resize(framesInFlight);
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = framesInFlight;
    check(vkAllocateCommandBuffers(device, &alloc, commandBuffers.data()), "vkAllocateCommandBuffers");
    for (std::uint32_t i = 0; i < framesInFlight; ++i) {
      VkFenceCreateInfo f{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
      f.flags = VK_FENCE_CREATE_SIGNALED_BIT;
      VkFence fence;
      check(vkCreateFence(device, &f, nullptr, &fence), "vkCreateFence");
      fences.push_back(fence);
    }
  }
};

}  // namespace sdfstream::test
