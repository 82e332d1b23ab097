// Context, part 1: the VkInstance and the validation messenger.
#include <atomic>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "gpu/check.h"
#include "gpu/context.h"

namespace sdfstream::gpu {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
std::atomic<std::uint64_t> processValidationMessages{0};

bool hasLayer(const char* name) {
  std::uint32_t count = 0;
  SDFSTREAM_VK(vkEnumerateInstanceLayerProperties(&count, nullptr));
  std::vector<VkLayerProperties> layers(count);
  SDFSTREAM_VK(vkEnumerateInstanceLayerProperties(&count, layers.data()));
  for (const auto& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return true;
  return false;
}

}  // namespace

std::uint64_t Context::processValidationMessageCount() { return processValidationMessages.load(); }

VKAPI_ATTR VkBool32 VKAPI_CALL Context::onValidationMessage(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT /*types*/,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<Context*>(user);
  self->validationMessages_.fetch_add(1);
  processValidationMessages.fetch_add(1);
  const char* level =
      (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
  std::fprintf(stderr, "[vulkan %s] %s\n", level, data && data->pMessage ? data->pMessage : "");
  std::fflush(stderr);
  return VK_FALSE;  // never abort the call: tests count messages and fail cleanly instead
}

VkDebugUtilsMessengerCreateInfoEXT Context::messengerInfo() {
  VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = &Context::onValidationMessage;
  info.pUserData = this;
  return info;
}

void Context::createMessenger() {
  const VkDebugUtilsMessengerCreateInfoEXT info = messengerInfo();
  auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
  SDFSTREAM_GPU_CHECK(create != nullptr, "VK_EXT_debug_utils enabled but not loadable");
  SDFSTREAM_VK(create(instance_, &info, nullptr, &messenger_));
  cmdBeginLabel_ = reinterpret_cast<PFN_vkCmdBeginDebugUtilsLabelEXT>(
      vkGetInstanceProcAddr(instance_, "vkCmdBeginDebugUtilsLabelEXT"));
  cmdEndLabel_ = reinterpret_cast<PFN_vkCmdEndDebugUtilsLabelEXT>(
      vkGetInstanceProcAddr(instance_, "vkCmdEndDebugUtilsLabelEXT"));
}

void Context::createInstance(bool validation) {
  if (validation && !hasLayer(kValidationLayer))
    throw std::runtime_error(
        "Vulkan validation was requested (ContextOptions::validation or SDFSTREAM_VALIDATION=1) "
        "but VK_LAYER_KHRONOS_validation is not installed (Debian: vulkan-validationlayers)");

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "sdfstream";
  app.pEngineName = "sdfstream";
  app.apiVersion = VK_API_VERSION_1_2;

  std::vector<const char*> layers, extensions;
  if (validation) {
    layers.push_back(kValidationLayer);
    // The validation layer itself provides VK_EXT_debug_utils, so it is always available here.
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  const VkDebugUtilsMessengerCreateInfoEXT messenger = messengerInfo();

  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  // Chaining the messenger info also reports problems inside vkCreate/DestroyInstance.
  info.pNext = validation ? &messenger : nullptr;
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  SDFSTREAM_VK(vkCreateInstance(&info, nullptr, &instance_));
  if (validation) createMessenger();
}

}  // namespace sdfstream::gpu
