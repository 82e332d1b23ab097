// A visibility buffer rasterized by a Vulkan graphics pipeline: for each pixel the triangle seen
// first (index + 1, 0 = nothing) and its barycentric coordinates (b1, b2) of vertices 1 and 2
// (Burns & Hunt 2013, "The Visibility Buffer"). Materials, normals and positions are resolved
// from these afterwards by the same functions the CPU references use, so the GPU's only job is
// the one it is best at: which triangle covers which pixel.
//
// The vertex stage pulls positions (vec4) and indices (uint, three per triangle) from storage
// buffers, so a draw is non-indexed with three vertices per triangle and needs no vertex input
// state. The caller picks the vertex/fragment pair (orthographic card views, perspective camera
// views), the depth rule, and per view a rectangle of the target and its push constants.
//
// Needs a queue family with graphics (Context::queueFamily); lavapipe, NVIDIA, AMD and Intel
// expose one. Move-only RAII owner; Vulkan objects are destroyed deferred. Thread safety: as for
// the Context.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include <vulkan/vulkan.h>

#include "shaders/embedded_shaders.h"

namespace sdfstream::gpu {
class Buffer;
class Context;
}  // namespace sdfstream::gpu

namespace sdfstream {

struct VisibilityStages {
  gpu::ShaderId vertex;
  gpu::ShaderId fragment;
  std::uint32_t pushBytes = 0;  // push constants of the vertex stage (at most 128)
  bool reverseDepth = false;    // depth cleared to 0 and GREATER wins (reverse-Z), else 1 / LESS
  std::string user;             // names the user in errors ("card capture", "raster primary")
};

// One view: a rectangle of the target and the vertex stage's push constants for it.
struct VisibilityView {
  std::uint32_t x = 0, y = 0, width = 0, height = 0;
  const void* push = nullptr;  // VisibilityStages::pushBytes bytes
};

class VisibilityRaster {
 public:
  // Throws std::runtime_error naming `stages.user` and what is missing when the Context's queue
  // has no graphics or the device cannot render to R32_UINT, R32G32_SFLOAT or D32_SFLOAT.
  VisibilityRaster(gpu::Context& ctx, const VisibilityStages& stages);
  ~VisibilityRaster();
  VisibilityRaster(VisibilityRaster&& other) noexcept;
  VisibilityRaster& operator=(VisibilityRaster&& other) noexcept;
  VisibilityRaster(const VisibilityRaster&) = delete;
  VisibilityRaster& operator=(const VisibilityRaster&) = delete;

  // Bytes `out` needs for a width x height visibility buffer: width·height triangle ids (uint),
  // then width·height barycentric pairs (vec2), both row-major from the top-left pixel.
  static std::size_t outputBytes(std::uint32_t width, std::uint32_t height) {
    return std::size_t(width) * height * 12;
  }

  // Records into `cb`: clears a width x height target, draws `triangleCount` triangles once per
  // view (each within its rectangle, inside the target), and copies the ids and barycentrics to
  // `out` (outputBytes; any transfer-destination buffer). The target grows on demand and is
  // kept; the buffers must stay alive until the submission completes.
  void record(VkCommandBuffer cb, const gpu::Buffer& positions, const gpu::Buffer& indices,
              std::uint32_t triangleCount, std::uint32_t width, std::uint32_t height,
              std::span<const VisibilityView> views, const gpu::Buffer& out);

 private:
  struct Target;  // the images, their views and memory, the framebuffer
  void createPipeline();
  void ensureTarget(std::uint32_t width, std::uint32_t height);
  void release();

  gpu::Context* ctx_ = nullptr;
  VisibilityStages stages_;
  VkRenderPass renderPass_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  std::unique_ptr<Target> target_;
};

}  // namespace sdfstream
