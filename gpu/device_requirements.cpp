#include "gpu/device_requirements.h"

#include <cstring>

namespace sdfstream::gpu {
namespace {

constexpr const char* kExtensions[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};

bool listed(std::span<const char* const> names, const char* name) {
  for (const char* n : names)
    if (n && std::strcmp(n, name) == 0) return true;
  return false;
}

std::string versionText(std::uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v));
}

}  // namespace

bool supportsExtension(VkPhysicalDevice device, const char* name) {
  std::uint32_t count = 0;
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
  for (const auto& e : extensions)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

std::span<const char* const> requiredExtensions() { return kExtensions; }

VkPhysicalDeviceVulkan12Features requiredFeatures12() {
  VkPhysicalDeviceVulkan12Features f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  f.timelineSemaphore = VK_TRUE;
  return f;
}

VkQueueFamilyProperties queueFamilyProperties(VkPhysicalDevice device, std::uint32_t family) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  return family < count ? families[family] : VkQueueFamilyProperties{};
}

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

std::vector<std::string> missingRequirements(VkPhysicalDevice device,
                                             const EnabledDeviceState* enabled) {
  std::vector<std::string> missing;
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(device, &props);
  if (props.apiVersion < VK_API_VERSION_1_2)
    missing.push_back("Vulkan 1.2 (device reports " + versionText(props.apiVersion) + ")");
  for (const char* name : kExtensions) {
    if (!supportsExtension(device, name))
      missing.push_back(std::string("extension ") + name + " (not supported)");
    else if (enabled && !listed(enabled->extensions, name))
      missing.push_back(std::string("extension ") + name + " (supported but not enabled)");
  }
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  f2.pNext = &f12;
  if (props.apiVersion >= VK_API_VERSION_1_1) vkGetPhysicalDeviceFeatures2(device, &f2);
  if (!f12.timelineSemaphore)
    missing.push_back("VkPhysicalDeviceVulkan12Features::timelineSemaphore (not supported)");
  else if (enabled && !(enabled->features12 && enabled->features12->timelineSemaphore))
    missing.push_back(
        "VkPhysicalDeviceVulkan12Features::timelineSemaphore (supported but not enabled)");
  if (findComputeFamily(device, nullptr) == UINT32_MAX) missing.push_back("a compute queue");
  // The probe passes add their per-ray counters per subgroup (shaders/probe_bindings.glsl).
  // Core properties, nothing to enable: every Vulkan 1.1 driver reports them.
  if (props.apiVersion >= VK_API_VERSION_1_1) {
    VkPhysicalDeviceSubgroupProperties sub{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    p2.pNext = &sub;
    vkGetPhysicalDeviceProperties2(device, &p2);
    const VkSubgroupFeatureFlags ops =
        VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
    if (!(sub.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) ||
        (sub.supportedOperations & ops) != ops)
      missing.push_back("basic and arithmetic subgroup operations in compute shaders");
  }
  return missing;
}

}  // namespace sdfstream::gpu
