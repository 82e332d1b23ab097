#include "gpu/compute_pipeline.h"

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "gpu/check.h"
#include "gpu/context.h"
#include "gpu/pipeline_statistics.h"
#include "gpu/spirv_info.h"

namespace sdfstream::gpu {

ComputePipeline::ComputePipeline(Context& ctx, ShaderId shader, const PipelineDesc& desc,
                                 std::optional<std::uint32_t> constant0)
    : ctx_(&ctx), shader_(shader), desc_(desc) {
  const std::span<const std::uint32_t> spirv = shaderSpirv(shader);
  const std::string who = std::string("pipeline ") + shaderName(shader) + ": ";
  if (auto local = spirvLocalSize(spirv))
    SDFSTREAM_GPU_CHECK(*local == desc.workgroupSize,
                        who + "PipelineDesc::workgroupSize differs from the shader's local_size");
  SDFSTREAM_GPU_CHECK(desc.pushConstantBytes % 4 == 0 &&
                          desc.pushConstantBytes <= ctx.properties().limits.maxPushConstantsSize,
                      who + "pushConstantBytes must be a multiple of 4 within the device limit");
  SDFSTREAM_GPU_CHECK(desc.storageBufferCount <= ctx.maxPushDescriptors(),
                      who + "more storage buffers than push descriptors allow");
  SDFSTREAM_GPU_CHECK(desc.workgroupSize.x * desc.workgroupSize.y * desc.workgroupSize.z > 0,
                      who + "empty workgroup");
  const VkPhysicalDeviceLimits& limits = ctx.properties().limits;
  SDFSTREAM_GPU_CHECK(desc.workgroupSize.x <= limits.maxComputeWorkGroupSize[0] &&
                          desc.workgroupSize.y <= limits.maxComputeWorkGroupSize[1] &&
                          desc.workgroupSize.z <= limits.maxComputeWorkGroupSize[2] &&
                          desc.workgroupSize.x * desc.workgroupSize.y * desc.workgroupSize.z <=
                              limits.maxComputeWorkGroupInvocations,
                      who + "workgroup larger than the device allows");

  VkDevice device = ctx.device();
  VkShaderModule module = VK_NULL_HANDLE;
  try {
    std::vector<VkDescriptorSetLayoutBinding> bindings(desc.storageBufferCount);
    for (std::uint32_t i = 0; i < desc.storageBufferCount; ++i)
      bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    setInfo.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
    setInfo.bindingCount = desc.storageBufferCount;
    setInfo.pBindings = bindings.data();
    SDFSTREAM_VK(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &setLayout_));

    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, desc.pushConstantBytes};
    VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layoutInfo.setLayoutCount = 1;
    layoutInfo.pSetLayouts = &setLayout_;
    layoutInfo.pushConstantRangeCount = desc.pushConstantBytes ? 1 : 0;
    layoutInfo.pPushConstantRanges = &range;
    SDFSTREAM_VK(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &layout_));

    VkShaderModuleCreateInfo moduleInfo{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    moduleInfo.codeSize = spirv.size_bytes();
    moduleInfo.pCode = spirv.data();
    SDFSTREAM_VK(vkCreateShaderModule(device, &moduleInfo, nullptr, &module));

    VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module;
    info.stage.pName = "main";
    const VkSpecializationMapEntry entry{0, 0, sizeof(std::uint32_t)};
    VkSpecializationInfo specialization{1, &entry, sizeof(std::uint32_t), nullptr};
    if (constant0) {
      specialization.pData = &*constant0;
      info.stage.pSpecializationInfo = &specialization;
    }
    info.layout = layout_;
    if (ctx.pipelineStatistics()) info.flags |= VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR;
    SDFSTREAM_VK(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_));
    if (ctx.pipelineStatistics())
      std::fprintf(stderr, "pipeline stats %s%s: %s\n", shaderName(shader),
                   constant0 ? (" (constant 0 = " + std::to_string(*constant0) + ")").c_str() : "",
                   pipelineStatisticsLine(device, pipeline_).c_str());
    // The pipeline keeps its own copy of the code; the module is only needed for creation.
    vkDestroyShaderModule(device, module, nullptr);
  } catch (...) {
    if (module) vkDestroyShaderModule(device, module, nullptr);
    if (layout_) vkDestroyPipelineLayout(device, layout_, nullptr);
    if (setLayout_) vkDestroyDescriptorSetLayout(device, setLayout_, nullptr);
    throw;
  }
}

ComputePipeline::~ComputePipeline() { release(); }

ComputePipeline::ComputePipeline(ComputePipeline&& other) noexcept
    : ctx_(std::exchange(other.ctx_, nullptr)),
      shader_(other.shader_),
      desc_(other.desc_),
      setLayout_(std::exchange(other.setLayout_, VK_NULL_HANDLE)),
      layout_(std::exchange(other.layout_, VK_NULL_HANDLE)),
      pipeline_(std::exchange(other.pipeline_, VK_NULL_HANDLE)) {}

ComputePipeline& ComputePipeline::operator=(ComputePipeline&& other) noexcept {
  if (this != &other) {
    release();
    ctx_ = std::exchange(other.ctx_, nullptr);
    shader_ = other.shader_;
    desc_ = other.desc_;
    setLayout_ = std::exchange(other.setLayout_, VK_NULL_HANDLE);
    layout_ = std::exchange(other.layout_, VK_NULL_HANDLE);
    pipeline_ = std::exchange(other.pipeline_, VK_NULL_HANDLE);
  }
  return *this;
}

ComputePipelinePair::ComputePipelinePair(Context& ctx, ShaderId shader, const PipelineDesc& desc)
    : ctx_(&ctx), shader_(shader), desc_(desc) {}

const ComputePipeline& ComputePipelinePair::variant(std::uint32_t constant0) {
  SDFSTREAM_GPU_CHECK(constant0 < kVariants, "ComputePipelinePair::variant out of range");
  ComputePipeline& v = variants_[constant0];
  if (!v) {
    SDFSTREAM_GPU_CHECK(ctx_ != nullptr, "ComputePipelinePair::get on an empty pair");
    v = ComputePipeline(*ctx_, shader_, desc_, constant0);
  }
  return v;
}

void ComputePipeline::release() {
  if (!pipeline_) return;
  ctx_->deferDestroy([device = ctx_->device(), p = pipeline_, l = layout_, s = setLayout_] {
    vkDestroyPipeline(device, p, nullptr);
    vkDestroyPipelineLayout(device, l, nullptr);
    vkDestroyDescriptorSetLayout(device, s, nullptr);
  });
  pipeline_ = VK_NULL_HANDLE;
  layout_ = VK_NULL_HANDLE;
  setLayout_ = VK_NULL_HANDLE;
}

}  // namespace sdfstream::gpu
