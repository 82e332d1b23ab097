// A compute pipeline built from an embedded shader (shaders/embedded_shaders.h).
//
// Resource binding contract: storage buffers are bindings 0..storageBufferCount-1 of set 0, and
// push constants one block of pushConstantBytes at offset 0. Descriptors are *push descriptors*
// (VK_KHR_push_descriptor): they are recorded into the command buffer by CommandBatch::dispatch,
// so there are no descriptor pools or sets to size, recycle or free late -- a batch owns nothing
// that outlives its command buffer. lavapipe, NVIDIA, AMD and Intel (Mesa) drivers support it;
// Context::create refuses devices without it.
//
// Move-only RAII owner; destruction is deferred like Buffer's. Thread safety: as for the Context.
#pragma once

#include <cstdint>
#include <optional>

#include <vulkan/vulkan.h>
#include <glm/vec3.hpp>

#include "shaders/embedded_shaders.h"

namespace sdfstream::gpu {

class Context;

struct PipelineDesc {
  std::uint32_t storageBufferCount = 0;  // <= Context::maxPushDescriptors() (>= 32)
  std::uint32_t pushConstantBytes = 0;   // multiple of 4, <= maxPushConstantsSize (>= 128)
  glm::uvec3 workgroupSize{1, 1, 1};     // must equal the shader's local_size (checked)
};

class ComputePipeline {
 public:
  ComputePipeline() = default;  // empty
  // Aborts (programmer error) when `desc` contradicts the shader's local size or device limits;
  // throws std::runtime_error when a Vulkan call fails.
  // constant0, where given, is the shader's specialization constant 0 (`layout(constant_id =
  // 0)`): a choice fixed when the pipeline is made, so the driver compiles only the code it picks
  // (a uniform branch keeps both paths in the program, which can cost a pass even where never
  // taken: registers, instruction cache).
  ComputePipeline(Context& ctx, ShaderId shader, const PipelineDesc& desc,
                  std::optional<std::uint32_t> constant0 = std::nullopt);
  ~ComputePipeline();
  ComputePipeline(ComputePipeline&& other) noexcept;
  ComputePipeline& operator=(ComputePipeline&& other) noexcept;
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;

  const PipelineDesc& desc() const { return desc_; }
  ShaderId shader() const { return shader_; }
  const char* name() const { return shaderName(shader_); }
  VkPipeline handle() const { return pipeline_; }
  VkPipelineLayout layout() const { return layout_; }
  explicit operator bool() const { return pipeline_ != VK_NULL_HANDLE; }

 private:
  void release();

  Context* ctx_ = nullptr;
  ShaderId shader_{};
  PipelineDesc desc_{};
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

// The pipelines of one shader by its specialization constant 0 (a bool, or up to kVariants
// values of option bits), each made on its first use: a run compiles only the variants it asks
// for. For passes whose choice is known only
// once the data is (which atlas a scene holds, gi/gpu_stack_scene.h). Asking for a variant not
// made yet creates it, a compile's hitch, once. Thread safety: as for the Context.
class ComputePipelinePair {
 public:
  ComputePipelinePair() = default;  // empty
  ComputePipelinePair(Context& ctx, ShaderId shader, const PipelineDesc& desc);

  // The variant with constant 0 = `on`. Throws std::runtime_error when creation fails.
  const ComputePipeline& get(bool on) { return variant(on ? 1u : 0u); }
  // The variant with constant 0 = `constant0` (< kVariants), for a shader whose constant 0 is a
  // uint of option bits (probe_sample.comp).
  const ComputePipeline& variant(std::uint32_t constant0);
  static constexpr std::uint32_t kVariants = 4;

 private:
  Context* ctx_ = nullptr;
  ShaderId shader_{};
  PipelineDesc desc_{};
  ComputePipeline variants_[kVariants];
};

}  // namespace sdfstream::gpu
