// The viewer's Vulkan device, owned the way an engine owns its own: an instance with the
// window system's surface extensions, the window's surface, a device that both presents to it
// and meets sdfstream's requirements, and a gpu::Context that adopts it (Context::adopt), so
// the GI runs on the engine's device as any host's would. Frames reach the window by a copy of
// the tone-mapped picture into the acquired swapchain image; the copy's submission signals the
// Context's timeline, so sdfstream knows when its buffers are free.
#pragma once

#include <memory>
#include <vector>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

#include "demo/frame_image.h"
#include "gpu/buffer.h"
#include "gpu/context.h"
#include "viewer/window.h"

namespace sdfstream::viewer {

class SwapchainPresenter {
 public:
  // options.device / $SDFSTREAM_DEVICE choose the device as for Context::create; validation as
  // there. vsync false: an immediate or mailbox present mode where the device offers one.
  // Throws std::runtime_error with one line (no device can present to the window, a surface
  // format that is not 8-bit RGBA/BGRA, ...).
  SwapchainPresenter(Window& window, const gpu::ContextOptions& options, bool vsync);
  ~SwapchainPresenter();
  SwapchainPresenter(const SwapchainPresenter&) = delete;
  SwapchainPresenter& operator=(const SwapchainPresenter&) = delete;

  gpu::Context& context() { return *context_; }

  // Matches the swapchain to the window's drawable size; returns the size frames must have
  // (0 x 0 while the window is minimised: skip presenting).
  glm::ivec2 prepare();
  // Shows `image` (sRGB-encoded, of the size prepare() returned). With `capture`, also reads
  // the presented swapchain image back (blocking). Returns false when the swapchain went out of
  // date and the frame was dropped (prepare() recreates it).
  bool present(const Image8& image, Image8* capture = nullptr);
  // Presentations made and swapchain recreations, for the HUD and tests.
  std::uint64_t presented() const { return presented_; }
  std::uint64_t recreations() const { return recreations_; }

 private:
  void createInstance(bool validation);
  void pickDevice(const gpu::ContextOptions& options);
  void createDevice(bool validation);
  void createSwapchain(glm::ivec2 size);
  void destroySwapchain();
  void release();

  Window& window_;
  bool vsync_;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice_ = VK_NULL_HANDLE;
  std::uint32_t queueFamily_ = 0;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::unique_ptr<gpu::Context> context_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;
  VkSemaphore imageAvailable_ = VK_NULL_HANDLE;
  std::uint64_t lastSubmission_ = 0;

  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  bool bgr_ = true;  // the swapchain stores B, G, R, A
  bool capturable_ = false;
  glm::ivec2 extent_{0};
  std::vector<VkImage> images_;
  std::vector<VkSemaphore> renderFinished_;  // one per image: presentation may still read one
  bool outOfDate_ = false;
  gpu::Buffer staging_, readback_;
  std::uint64_t presented_ = 0, recreations_ = 0;
};

}  // namespace sdfstream::viewer
