// What sdfstream needs of a Vulkan device, checked in one place for both ways a Context gets one:
// choosing a physical device of its own (Context::create) and adopting an engine's device
// (Context::adopt), where the engine must also have enabled the features at vkCreateDevice.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace sdfstream::gpu {

// Device extensions sdfstream records with (push descriptors for every pass).
std::span<const char* const> requiredExtensions();
// The Vulkan 1.2 features it uses, set to VK_TRUE (timeline semaphores for the submission
// timeline and deferred destruction).
VkPhysicalDeviceVulkan12Features requiredFeatures12();

// What `device` lacks, one short phrase each ("Vulkan 1.2 (device reports 1.1)", "extension
// VK_KHR_push_descriptor", ...); empty = suitable. With `enabled` given (an adopted VkDevice),
// also what the device supports but the engine did not enable.
struct EnabledDeviceState {
  std::span<const char* const> extensions;
  const VkPhysicalDeviceVulkan12Features* features12 = nullptr;
};
std::vector<std::string> missingRequirements(VkPhysicalDevice device,
                                             const EnabledDeviceState* enabled = nullptr);

// True when `device` offers the device extension `name`.
bool supportsExtension(VkPhysicalDevice device, const char* name);

// The family to submit compute work to: the first with compute, preferring one with timestamps.
// UINT32_MAX when there is none. `timestampBits` (optional) receives its timestampValidBits.
std::uint32_t findComputeFamily(VkPhysicalDevice device, std::uint32_t* timestampBits);

// Properties of one queue family (bounds-checked: UINT32_MAX family -> flags 0).
VkQueueFamilyProperties queueFamilyProperties(VkPhysicalDevice device, std::uint32_t family);

}  // namespace sdfstream::gpu
