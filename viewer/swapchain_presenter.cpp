#include "viewer/swapchain_presenter.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "gpu/check.h"
#include "gpu/device_requirements.h"
#include "gpu/device_select.h"

namespace sdfstream::viewer {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

bool envFlag(const char* name) {
  const char* v = std::getenv(name);
  return v && std::strcmp(v, "1") == 0;
}

// The first queue family that runs compute and presents to `surface`, preferring one with
// timestamps (the GI's pass times); UINT32_MAX when there is none.
std::uint32_t presentComputeFamily(VkPhysicalDevice device, VkSurfaceKHR surface) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  std::uint32_t best = UINT32_MAX;
  for (std::uint32_t f = 0; f < count; ++f) {
    VkBool32 present = VK_FALSE;
    vkGetPhysicalDeviceSurfaceSupportKHR(device, f, surface, &present);
    if (!present || !(families[f].queueFlags & VK_QUEUE_COMPUTE_BIT)) continue;
    if (families[f].timestampValidBits) return f;
    if (best == UINT32_MAX) best = f;
  }
  return best;
}

void barrier(VkCommandBuffer cb, VkImage image, VkAccessFlags srcAccess, VkAccessFlags dstAccess,
             VkImageLayout from, VkImageLayout to, VkPipelineStageFlags srcStage,
             VkPipelineStageFlags dstStage) {
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.srcAccessMask = srcAccess;
  b.dstAccessMask = dstAccess;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cb, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
}

}  // namespace

SwapchainPresenter::SwapchainPresenter(Window& window, const gpu::ContextOptions& options,
                                       bool vsync)
    : window_(window), vsync_(vsync) {
  const bool validation = options.validation || envFlag("SDFSTREAM_VALIDATION");
  try {
    createInstance(validation);
    SDFSTREAM_VK(glfwCreateWindowSurface(instance_, window.handle(), nullptr, &surface_));
    pickDevice(options);
    createDevice(validation);
    VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = queueFamily_;
    SDFSTREAM_VK(vkCreateCommandPool(device_, &pool, nullptr, &pool_));
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = pool_;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    SDFSTREAM_VK(vkAllocateCommandBuffers(device_, &alloc, &commands_));
    VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    SDFSTREAM_VK(vkCreateSemaphore(device_, &si, nullptr, &imageAvailable_));
  } catch (...) {
    release();
    throw;
  }
}

SwapchainPresenter::~SwapchainPresenter() { release(); }

// Idempotent: the constructor's failure path and the destructor both call it.
void SwapchainPresenter::release() {
  if (device_) vkDeviceWaitIdle(device_);
  staging_ = gpu::Buffer();
  readback_ = gpu::Buffer();
  context_.reset();  // runs its deferred destructions; the device must outlive it
  destroySwapchain();
  if (imageAvailable_) vkDestroySemaphore(device_, imageAvailable_, nullptr);
  if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
  if (device_) vkDestroyDevice(device_, nullptr);
  if (surface_) vkDestroySurfaceKHR(instance_, surface_, nullptr);
  if (instance_) vkDestroyInstance(instance_, nullptr);
  imageAvailable_ = VK_NULL_HANDLE;
  pool_ = VK_NULL_HANDLE;
  device_ = VK_NULL_HANDLE;
  surface_ = VK_NULL_HANDLE;
  instance_ = VK_NULL_HANDLE;
}

void SwapchainPresenter::createInstance(bool validation) {
  std::uint32_t count = 0;
  const char** glfwExtensions = glfwGetRequiredInstanceExtensions(&count);
  if (!glfwExtensions)
    throw std::runtime_error("the Vulkan loader offers no surface for this window system");
  std::vector<const char*> extensions(glfwExtensions, glfwExtensions + count), layers;
  if (validation) {
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "sdfstream view";
  app.pEngineName = "sdfstream";
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  info.enabledLayerCount = std::uint32_t(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = std::uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  const VkResult r = vkCreateInstance(&info, nullptr, &instance_);
  if (r == VK_ERROR_LAYER_NOT_PRESENT)
    throw std::runtime_error(
        "Vulkan validation was requested (SDFSTREAM_VALIDATION=1) but VK_LAYER_KHRONOS_validation "
        "is not installed (Debian: vulkan-validationlayers)");
  SDFSTREAM_VK(r);
}

void SwapchainPresenter::pickDevice(const gpu::ContextOptions& options) {
  std::uint32_t count = 0;
  SDFSTREAM_VK(vkEnumeratePhysicalDevices(instance_, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  SDFSTREAM_VK(vkEnumeratePhysicalDevices(instance_, &count, devices.data()));
  std::vector<gpu::DeviceCandidate> candidates;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    std::vector<std::string> missing = gpu::missingRequirements(d);
    if (presentComputeFamily(d, surface_) == UINT32_MAX)
      missing.push_back("a compute queue that presents to the window");
    std::string reason;
    for (const std::string& m : missing) reason += (reason.empty() ? "lacks " : ", ") + m;
    candidates.push_back({p.deviceName, p.deviceType, reason});
  }
  std::string request = options.device, source = "--device";
  if (const char* env = std::getenv("SDFSTREAM_DEVICE"); request.empty() && env && *env) {
    request = env;
    source = "SDFSTREAM_DEVICE";
  }
  physicalDevice_ = devices[gpu::selectDevice(candidates, request, source)];
  queueFamily_ = presentComputeFamily(physicalDevice_, surface_);
}

void SwapchainPresenter::createDevice(bool validation) {
  const auto required = gpu::Context::requiredDeviceExtensions();
  std::vector<const char*> extensions(required.begin(), required.end());
  extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  VkPhysicalDeviceVulkan12Features features12 = gpu::Context::requiredVulkan12Features();
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue.queueFamilyIndex = queueFamily_;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.pNext = &features12;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue;
  info.enabledExtensionCount = std::uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  SDFSTREAM_VK(vkCreateDevice(physicalDevice_, &info, nullptr, &device_));
  vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);

  gpu::AdoptedDevice adopted;
  adopted.instance = instance_;
  adopted.physicalDevice = physicalDevice_;
  adopted.device = device_;
  adopted.queueFamily = queueFamily_;
  adopted.queueIndex = 0;
  adopted.enabledDeviceExtensions = extensions;
  adopted.enabledVulkan12Features = features12;
  adopted.instanceHasDebugUtils = validation;
  gpu::ContextOptions options;
  options.validation = validation;
  context_ = gpu::Context::adopt(adopted, options);
}

void SwapchainPresenter::createSwapchain(glm::ivec2 size) {
  VkSurfaceCapabilitiesKHR caps;
  SDFSTREAM_VK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physicalDevice_, surface_, &caps));
  std::uint32_t count = 0;
  SDFSTREAM_VK(vkGetPhysicalDeviceSurfaceFormatsKHR(physicalDevice_, surface_, &count, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(count);
  SDFSTREAM_VK(
      vkGetPhysicalDeviceSurfaceFormatsKHR(physicalDevice_, surface_, &count, formats.data()));
  // The picture is already sRGB-encoded bytes: a copy into a UNORM image shows them as they
  // are, and so does one into an _SRGB image (copies do not convert).
  const VkFormat preferred[] = {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM,
                                VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R8G8B8A8_SRGB};
  VkSurfaceFormatKHR chosen{VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
  for (VkFormat want : preferred)
    for (const VkSurfaceFormatKHR& f : formats)
      if (chosen.format == VK_FORMAT_UNDEFINED && f.format == want &&
          f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR)
        chosen = f;
  if (chosen.format == VK_FORMAT_UNDEFINED)
    throw std::runtime_error("the window's surface offers no 8-bit RGBA/BGRA sRGB format");
  format_ = chosen.format;
  bgr_ = format_ == VK_FORMAT_B8G8R8A8_UNORM || format_ == VK_FORMAT_B8G8R8A8_SRGB;
  if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
    throw std::runtime_error("the window's swapchain images cannot be copied to");
  capturable_ = caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT;

  VkExtent2D extent = caps.currentExtent;
  if (extent.width == UINT32_MAX) {
    extent.width =
        std::clamp(std::uint32_t(size.x), caps.minImageExtent.width, caps.maxImageExtent.width);
    extent.height =
        std::clamp(std::uint32_t(size.y), caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  std::uint32_t modeCount = 0;
  vkGetPhysicalDeviceSurfacePresentModesKHR(physicalDevice_, surface_, &modeCount, nullptr);
  std::vector<VkPresentModeKHR> modes(modeCount);
  vkGetPhysicalDeviceSurfacePresentModesKHR(physicalDevice_, surface_, &modeCount, modes.data());
  VkPresentModeKHR mode = VK_PRESENT_MODE_FIFO_KHR;  // always offered
  if (!vsync_)
    for (VkPresentModeKHR m : {VK_PRESENT_MODE_MAILBOX_KHR, VK_PRESENT_MODE_IMMEDIATE_KHR})
      if (mode == VK_PRESENT_MODE_FIFO_KHR &&
          std::find(modes.begin(), modes.end(), m) != modes.end())
        mode = m;

  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = surface_;
  info.minImageCount = caps.maxImageCount ? std::min(caps.minImageCount + 1, caps.maxImageCount)
                                          : caps.minImageCount + 1;
  info.imageFormat = chosen.format;
  info.imageColorSpace = chosen.colorSpace;
  info.imageExtent = extent;
  info.imageArrayLayers = 1;
  info.imageUsage =
      VK_IMAGE_USAGE_TRANSFER_DST_BIT | (capturable_ ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0);
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                            ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                            : VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha &
                                                          -caps.supportedCompositeAlpha);
  info.presentMode = mode;
  info.clipped = VK_TRUE;
  SDFSTREAM_VK(vkCreateSwapchainKHR(device_, &info, nullptr, &swapchain_));
  SDFSTREAM_VK(vkGetSwapchainImagesKHR(device_, swapchain_, &count, nullptr));
  images_.resize(count);
  SDFSTREAM_VK(vkGetSwapchainImagesKHR(device_, swapchain_, &count, images_.data()));
  VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  renderFinished_.resize(count);
  for (VkSemaphore& s : renderFinished_) SDFSTREAM_VK(vkCreateSemaphore(device_, &si, nullptr, &s));
  extent_ = {int(extent.width), int(extent.height)};
  outOfDate_ = false;
}

void SwapchainPresenter::destroySwapchain() {
  for (VkSemaphore s : renderFinished_) vkDestroySemaphore(device_, s, nullptr);
  renderFinished_.clear();
  images_.clear();
  if (swapchain_) vkDestroySwapchainKHR(device_, swapchain_, nullptr);
  swapchain_ = VK_NULL_HANDLE;
  extent_ = glm::ivec2(0);
}

glm::ivec2 SwapchainPresenter::prepare() {
  const glm::ivec2 size = window_.framebufferSize();
  if (size.x <= 0 || size.y <= 0) return glm::ivec2(0);
  if (swapchain_ && !outOfDate_ && size == extent_) return extent_;
  if (swapchain_) {
    // Presentation may still read the old images: let the queue drain first.
    vkQueueWaitIdle(queue_);
    destroySwapchain();
    ++recreations_;
  }
  createSwapchain(size);
  return extent_;
}

bool SwapchainPresenter::present(const Image8& image, Image8* capture) {
  if (!swapchain_ || image.width != extent_.x || image.height != extent_.y)
    throw std::logic_error("SwapchainPresenter::present: the image is not the swapchain's size");
  if (capture && !capturable_)
    throw std::runtime_error(
        "this device's swapchain images cannot be read back (no "
        "VK_IMAGE_USAGE_TRANSFER_SRC_BIT): no capture");
  // The previous copy must be done before its staging buffer and command buffer are reused.
  if (lastSubmission_) context_->wait(lastSubmission_);

  std::uint32_t index = 0;
  const VkResult acquired = vkAcquireNextImageKHR(device_, swapchain_, UINT64_MAX, imageAvailable_,
                                                  VK_NULL_HANDLE, &index);
  if (acquired == VK_ERROR_OUT_OF_DATE_KHR) {
    outOfDate_ = true;
    return false;
  }
  if (acquired != VK_SUBOPTIMAL_KHR) SDFSTREAM_VK(acquired);

  const std::size_t bytes = std::size_t(extent_.x) * std::size_t(extent_.y) * 4;
  if (staging_.size() < bytes) staging_ = gpu::Buffer(*context_, bytes, gpu::BufferKind::Upload);
  auto* out = static_cast<std::uint8_t*>(staging_.mapped());
  const std::size_t pixels = std::size_t(extent_.x) * std::size_t(extent_.y);
  for (std::size_t p = 0; p < pixels; ++p) {
    const std::uint8_t* in = &image.rgb[3 * p];
    out[4 * p + 0] = bgr_ ? in[2] : in[0];
    out[4 * p + 1] = in[1];
    out[4 * p + 2] = bgr_ ? in[0] : in[2];
    out[4 * p + 3] = 255;
  }
  if (capture && readback_.size() < bytes)
    readback_ = gpu::Buffer(*context_, bytes, gpu::BufferKind::Readback);

  SDFSTREAM_VK(vkResetCommandBuffer(commands_, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  SDFSTREAM_VK(vkBeginCommandBuffer(commands_, &begin));
  const VkImage target = images_[index];
  barrier(commands_, target, 0, VK_ACCESS_TRANSFER_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
          VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
          VK_PIPELINE_STAGE_TRANSFER_BIT);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {std::uint32_t(extent_.x), std::uint32_t(extent_.y), 1};
  vkCmdCopyBufferToImage(commands_, staging_.handle(), target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         1, &region);
  VkImageLayout layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  VkAccessFlags access = VK_ACCESS_TRANSFER_WRITE_BIT;
  if (capture) {
    barrier(commands_, target, VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT, layout,
            VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
            VK_PIPELINE_STAGE_TRANSFER_BIT);
    vkCmdCopyImageToBuffer(commands_, target, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           readback_.handle(), 1, &region);
    layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    access = VK_ACCESS_TRANSFER_READ_BIT;
    VkBufferMemoryBarrier toHost{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    toHost.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    toHost.srcQueueFamilyIndex = toHost.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    toHost.buffer = readback_.handle();
    toHost.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0,
                         0, nullptr, 1, &toHost, 0, nullptr);
  }
  barrier(commands_, target, access, 0, layout, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
          VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  SDFSTREAM_VK(vkEndCommandBuffer(commands_));

  // Signal the Context's timeline too: it then frees the buffers this copy reads only after it.
  const gpu::SubmitSignal signal = context_->reserveSubmission();
  const VkSemaphore signals[2] = {renderFinished_[index], signal.semaphore};
  const std::uint64_t values[2] = {0, signal.value};
  VkTimelineSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  timeline.signalSemaphoreValueCount = 2;
  timeline.pSignalSemaphoreValues = values;
  const VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.pNext = &timeline;
  submit.waitSemaphoreCount = 1;
  submit.pWaitSemaphores = &imageAvailable_;
  submit.pWaitDstStageMask = &waitStage;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &commands_;
  submit.signalSemaphoreCount = 2;
  submit.pSignalSemaphores = signals;
  SDFSTREAM_VK(vkQueueSubmit(queue_, 1, &submit, VK_NULL_HANDLE));
  lastSubmission_ = signal.value;

  VkPresentInfoKHR info{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  info.waitSemaphoreCount = 1;
  info.pWaitSemaphores = &renderFinished_[index];
  info.swapchainCount = 1;
  info.pSwapchains = &swapchain_;
  info.pImageIndices = &index;
  const VkResult shown = vkQueuePresentKHR(queue_, &info);
  if (shown == VK_ERROR_OUT_OF_DATE_KHR || shown == VK_SUBOPTIMAL_KHR ||
      acquired == VK_SUBOPTIMAL_KHR)
    outOfDate_ = true;
  else
    SDFSTREAM_VK(shown);
  ++presented_;

  if (capture) {
    context_->wait(lastSubmission_);
    const auto* in = static_cast<const std::uint8_t*>(readback_.mapped());
    capture->width = extent_.x;
    capture->height = extent_.y;
    capture->rgb.resize(pixels * 3);
    for (std::size_t p = 0; p < pixels; ++p) {
      capture->rgb[3 * p + 0] = bgr_ ? in[4 * p + 2] : in[4 * p + 0];
      capture->rgb[3 * p + 1] = in[4 * p + 1];
      capture->rgb[3 * p + 2] = bgr_ ? in[4 * p + 0] : in[4 * p + 2];
    }
  }
  return true;
}

}  // namespace sdfstream::viewer
