// The GPU side of card capture: a Vulkan graphics pipeline rasterizes a mesh's six orthographic
// card views (cards/card_layout.h) side by side into one visibility target (triangle + 1 as
// R32_UINT, barycentrics as R32G32_SFLOAT, a D32 depth test), in one submission, and reads it
// back as CardVisibility in the cards' texel order. Capture runs once per mesh (its attributes
// are object-space), so a blocking readback is fine; captureCardsCpu (card_capture.h) is the
// reference it is tested against.
//
// Needs a queue family with graphics (Context::queueFamily); lavapipe, NVIDIA, AMD and Intel
// expose one. Move-only RAII owner; Vulkan objects are destroyed deferred. Thread safety: as for
// the Context.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <vulkan/vulkan.h>

#include "cards/card_capture.h"

namespace sdfstream::gpu {
class Context;
}

namespace sdfstream {

class CardRasterizer {
 public:
  // Throws std::runtime_error naming what is missing when the Context's queue has no graphics
  // or the device cannot render to the target formats (R32_UINT, R32G32_SFLOAT, D32_SFLOAT).
  explicit CardRasterizer(gpu::Context& ctx);
  ~CardRasterizer();
  CardRasterizer(CardRasterizer&& other) noexcept;
  CardRasterizer& operator=(CardRasterizer&& other) noexcept;
  CardRasterizer(const CardRasterizer&) = delete;
  CardRasterizer& operator=(const CardRasterizer&) = delete;

  // One sample per card texel (MeshCards texel order). Blocks until the GPU is done. The mesh
  // must have passed validateObjectMesh (indices in range).
  std::vector<CardVisibility> capture(const TriangleScene& mesh, const MeshCards& cards);
  // GPU time of the last capture's draw + readback copies (0 without timestamps).
  double lastMilliseconds() const { return lastMilliseconds_; }

 private:
  struct Target;  // the images, their views and memory, the framebuffer
  void createPipeline();
  void ensureTarget(std::uint32_t width, std::uint32_t height);
  void release();

  gpu::Context* ctx_ = nullptr;
  VkRenderPass renderPass_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  std::unique_ptr<Target> target_;
  double lastMilliseconds_ = 0.0;
};

}  // namespace sdfstream
