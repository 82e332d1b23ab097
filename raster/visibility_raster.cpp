#include "raster/visibility_raster.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <utility>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/check.h"
#include "gpu/context.h"
#include "gpu/memory_type.h"

namespace sdfstream {
namespace {

constexpr VkFormat kIdFormat = VK_FORMAT_R32_UINT;
constexpr VkFormat kBaryFormat = VK_FORMAT_R32G32_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

void requireFormat(VkPhysicalDevice device, VkFormat format, VkFormatFeatureFlags features,
                   const std::string& user, const char* what) {
  VkFormatProperties props;
  vkGetPhysicalDeviceFormatProperties(device, format, &props);
  if ((props.optimalTilingFeatures & features) != features)
    throw std::runtime_error(user + ": the device cannot render " + what);
}

VkShaderModule shaderModule(VkDevice device, gpu::ShaderId id) {
  const auto words = gpu::shaderSpirv(id);
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = words.size() * sizeof(std::uint32_t);
  info.pCode = words.data();
  VkShaderModule module = VK_NULL_HANDLE;
  SDFSTREAM_VK(vkCreateShaderModule(device, &info, nullptr, &module));
  return module;
}

}  // namespace

// The three images with their memory and views, and the framebuffer; destroyed deferred (a
// submitted draw may still use them).
struct VisibilityRaster::Target {
  struct Image {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
  };
  gpu::Context* ctx = nullptr;
  std::string user;
  std::uint32_t width = 0, height = 0;
  Image id, bary, depth;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;

  Image create(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect) {
    VkDevice device = ctx->device();
    Image out;
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {width, height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    SDFSTREAM_VK(vkCreateImage(device, &info, nullptr, &out.image));
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, out.image, &req);
    auto type = gpu::findMemoryType(ctx->memoryProperties(), req.memoryTypeBits,
                                    {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0, 0});
    if (!type) type = gpu::findMemoryType(ctx->memoryProperties(), req.memoryTypeBits, {});
    if (!type) {
      vkDestroyImage(device, out.image, nullptr);
      throw std::runtime_error(user + ": no memory type fits the visibility target");
    }
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = *type;
    SDFSTREAM_VK(vkAllocateMemory(device, &alloc, nullptr, &out.memory));
    SDFSTREAM_VK(vkBindImageMemory(device, out.image, out.memory, 0));
    VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = out.image;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = {aspect, 0, 1, 0, 1};
    SDFSTREAM_VK(vkCreateImageView(device, &view, nullptr, &out.view));
    return out;
  }

  ~Target() {
    if (!ctx) return;
    ctx->deferDestroy([device = ctx->device(), images = std::array<Image, 3>{id, bary, depth},
                       framebuffer = framebuffer] {
      if (framebuffer) vkDestroyFramebuffer(device, framebuffer, nullptr);
      for (const Image& i : images) {
        if (i.view) vkDestroyImageView(device, i.view, nullptr);
        if (i.image) vkDestroyImage(device, i.image, nullptr);
        if (i.memory) vkFreeMemory(device, i.memory, nullptr);
      }
    });
  }
};

VisibilityRaster::VisibilityRaster(gpu::Context& ctx, const VisibilityStages& stages)
    : ctx_(&ctx), stages_(stages) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(ctx.physicalDevice(), &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(ctx.physicalDevice(), &count, families.data());
  if (ctx.queueFamily() >= count ||
      !(families[ctx.queueFamily()].queueFlags & VK_QUEUE_GRAPHICS_BIT))
    throw std::runtime_error(stages.user + ": queue family " + std::to_string(ctx.queueFamily()) +
                             " of " + ctx.deviceName() + " has no graphics");
  constexpr VkFormatFeatureFlags color =
      VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
  requireFormat(ctx.physicalDevice(), kIdFormat, color, stages.user, "to R32_UINT");
  requireFormat(ctx.physicalDevice(), kBaryFormat, color, stages.user, "to R32G32_SFLOAT");
  requireFormat(ctx.physicalDevice(), kDepthFormat, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT,
                stages.user, "depth to D32_SFLOAT");
  try {
    createPipeline();
  } catch (...) {
    release();
    throw;
  }
}

VisibilityRaster::~VisibilityRaster() { release(); }

VisibilityRaster::VisibilityRaster(VisibilityRaster&& other) noexcept
    : ctx_(std::exchange(other.ctx_, nullptr)),
      stages_(std::move(other.stages_)),
      renderPass_(std::exchange(other.renderPass_, VK_NULL_HANDLE)),
      setLayout_(std::exchange(other.setLayout_, VK_NULL_HANDLE)),
      layout_(std::exchange(other.layout_, VK_NULL_HANDLE)),
      pipeline_(std::exchange(other.pipeline_, VK_NULL_HANDLE)),
      target_(std::move(other.target_)) {}

VisibilityRaster& VisibilityRaster::operator=(VisibilityRaster&& other) noexcept {
  if (this != &other) {
    release();
    ctx_ = std::exchange(other.ctx_, nullptr);
    stages_ = std::move(other.stages_);
    renderPass_ = std::exchange(other.renderPass_, VK_NULL_HANDLE);
    setLayout_ = std::exchange(other.setLayout_, VK_NULL_HANDLE);
    layout_ = std::exchange(other.layout_, VK_NULL_HANDLE);
    pipeline_ = std::exchange(other.pipeline_, VK_NULL_HANDLE);
    target_ = std::move(other.target_);
  }
  return *this;
}

void VisibilityRaster::release() {
  target_.reset();
  if (!ctx_) return;
  ctx_->deferDestroy([device = ctx_->device(), pass = renderPass_, set = setLayout_,
                      layout = layout_, pipeline = pipeline_] {
    if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
    if (layout) vkDestroyPipelineLayout(device, layout, nullptr);
    if (set) vkDestroyDescriptorSetLayout(device, set, nullptr);
    if (pass) vkDestroyRenderPass(device, pass, nullptr);
  });
  renderPass_ = VK_NULL_HANDLE;
  setLayout_ = VK_NULL_HANDLE;
  layout_ = VK_NULL_HANDLE;
  pipeline_ = VK_NULL_HANDLE;
  ctx_ = nullptr;
}

void VisibilityRaster::createPipeline() {
  VkDevice device = ctx_->device();
  // Render pass: two colour targets and depth, cleared; the colours end ready to be copied out.
  std::array<VkAttachmentDescription, 3> attachments{};
  const VkFormat formats[3] = {kIdFormat, kBaryFormat, kDepthFormat};
  for (int i = 0; i < 3; ++i) {
    attachments[i].format = formats[i];
    attachments[i].samples = VK_SAMPLE_COUNT_1_BIT;
    attachments[i].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    attachments[i].storeOp =
        i < 2 ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE;
    attachments[i].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    attachments[i].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    attachments[i].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    attachments[i].finalLayout = i < 2 ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL
                                       : VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  }
  const VkAttachmentReference colorRefs[2] = {{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL},
                                              {1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL}};
  const VkAttachmentReference depthRef{2, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 2;
  subpass.pColorAttachments = colorRefs;
  subpass.pDepthStencilAttachment = &depthRef;
  // Before: the previous draw's copies out of the same images (write after read). After: the
  // copies of this one read what the pass wrote.
  constexpr VkPipelineStageFlags kAttachmentStages = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                                                     VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                                                     VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  std::array<VkSubpassDependency, 2> deps{};
  deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  deps[0].dstSubpass = 0;
  deps[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT | kAttachmentStages;
  deps[0].dstStageMask = kAttachmentStages;
  deps[0].srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  deps[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  deps[1].srcSubpass = 0;
  deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkRenderPassCreateInfo passInfo{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  passInfo.attachmentCount = 3;
  passInfo.pAttachments = attachments.data();
  passInfo.subpassCount = 1;
  passInfo.pSubpasses = &subpass;
  passInfo.dependencyCount = 2;
  passInfo.pDependencies = deps.data();
  SDFSTREAM_VK(vkCreateRenderPass(device, &passInfo, nullptr, &renderPass_));

  // Positions and indices pulled by the vertex shader, as push descriptors (like the compute
  // passes: nothing to pool or free).
  std::array<VkDescriptorSetLayoutBinding, 2> bindings{};
  for (std::uint32_t i = 0; i < 2; ++i)
    bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  setInfo.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
  setInfo.bindingCount = 2;
  setInfo.pBindings = bindings.data();
  SDFSTREAM_VK(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &setLayout_));
  const VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT, 0, stages_.pushBytes};
  VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layoutInfo.setLayoutCount = 1;
  layoutInfo.pSetLayouts = &setLayout_;
  layoutInfo.pushConstantRangeCount = stages_.pushBytes ? 1 : 0;
  layoutInfo.pPushConstantRanges = &range;
  SDFSTREAM_VK(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &layout_));

  VkShaderModule vs = shaderModule(device, stages_.vertex);
  VkShaderModule fs = VK_NULL_HANDLE;
  try {
    fs = shaderModule(device, stages_.fragment);
  } catch (...) {
    vkDestroyShaderModule(device, vs, nullptr);
    throw;
  }
  std::array<VkPipelineShaderStageCreateInfo, 2> stageInfo{};
  stageInfo[0] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  stageInfo[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stageInfo[0].module = vs;
  stageInfo[0].pName = "main";
  stageInfo[1] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  stageInfo[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stageInfo[1].module = fs;
  stageInfo[1].pName = "main";
  VkPipelineVertexInputStateCreateInfo vertexInput{
      VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  VkPipelineInputAssemblyStateCreateInfo assembly{
      VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  viewport.viewportCount = 1;
  viewport.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo raster{
      VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = VK_CULL_MODE_NONE;  // open sheets are seen from either side (the SDF's rule)
  raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  raster.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo multisample{
      VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo depth{
      VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  depth.depthTestEnable = VK_TRUE;
  depth.depthWriteEnable = VK_TRUE;
  // Equal depths: the first triangle drawn stays.
  depth.depthCompareOp = stages_.reverseDepth ? VK_COMPARE_OP_GREATER : VK_COMPARE_OP_LESS;
  std::array<VkPipelineColorBlendAttachmentState, 2> blend{};
  // Identical states (independentBlend is optional); components a format lacks are ignored.
  for (auto& b : blend)
    b.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                       VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
  VkPipelineColorBlendStateCreateInfo blendInfo{
      VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  blendInfo.attachmentCount = 2;
  blendInfo.pAttachments = blend.data();
  const VkDynamicState dynamicStates[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dynamic.dynamicStateCount = 2;
  dynamic.pDynamicStates = dynamicStates;
  VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  info.stageCount = 2;
  info.pStages = stageInfo.data();
  info.pVertexInputState = &vertexInput;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &viewport;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &multisample;
  info.pDepthStencilState = &depth;
  info.pColorBlendState = &blendInfo;
  info.pDynamicState = &dynamic;
  info.layout = layout_;
  info.renderPass = renderPass_;
  const VkResult created =
      vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_);
  vkDestroyShaderModule(device, vs, nullptr);
  vkDestroyShaderModule(device, fs, nullptr);
  SDFSTREAM_VK(created);
}

void VisibilityRaster::ensureTarget(std::uint32_t width, std::uint32_t height) {
  if (target_ && target_->width >= width && target_->height >= height) return;
  if (target_) {  // grow to cover both, so alternating sizes do not thrash
    width = std::max(width, target_->width);
    height = std::max(height, target_->height);
  }
  target_.reset();
  auto t = std::make_unique<Target>();
  t->ctx = ctx_;
  t->user = stages_.user;
  t->width = width;
  t->height = height;
  constexpr VkImageUsageFlags color =
      VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  t->id = t->create(kIdFormat, color, VK_IMAGE_ASPECT_COLOR_BIT);
  t->bary = t->create(kBaryFormat, color, VK_IMAGE_ASPECT_COLOR_BIT);
  t->depth = t->create(kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                       VK_IMAGE_ASPECT_DEPTH_BIT);
  const VkImageView views[3] = {t->id.view, t->bary.view, t->depth.view};
  VkFramebufferCreateInfo info{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  info.renderPass = renderPass_;
  info.attachmentCount = 3;
  info.pAttachments = views;
  info.width = width;
  info.height = height;
  info.layers = 1;
  SDFSTREAM_VK(vkCreateFramebuffer(ctx_->device(), &info, nullptr, &t->framebuffer));
  target_ = std::move(t);
}

void VisibilityRaster::record(VkCommandBuffer cb, const gpu::Buffer& positions,
                              const gpu::Buffer& indices, std::uint32_t triangleCount,
                              std::uint32_t width, std::uint32_t height,
                              std::span<const VisibilityView> views, const gpu::Buffer& out) {
  ensureTarget(width, height);
  VkClearValue clears[3]{};
  clears[0].color.uint32[0] = 0;
  clears[2].depthStencil = {stages_.reverseDepth ? 0.0f : 1.0f, 0};
  VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  begin.renderPass = renderPass_;
  begin.framebuffer = target_->framebuffer;
  begin.renderArea = {{0, 0}, {width, height}};
  begin.clearValueCount = 3;
  begin.pClearValues = clears;
  vkCmdBeginRenderPass(cb, &begin, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
  VkDescriptorBufferInfo infos[2] = {{positions.handle(), 0, VK_WHOLE_SIZE},
                                     {indices.handle(), 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSet writes[2]{};
  for (std::uint32_t i = 0; i < 2; ++i) {
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  ctx_->cmdPushDescriptorSet()(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 2, writes);
  for (const VisibilityView& v : views) {
    const VkViewport viewport{float(v.x), float(v.y), float(v.width), float(v.height), 0.0f, 1.0f};
    const VkRect2D scissor{{std::int32_t(v.x), std::int32_t(v.y)}, {v.width, v.height}};
    vkCmdSetViewport(cb, 0, 1, &viewport);
    vkCmdSetScissor(cb, 0, 1, &scissor);
    if (stages_.pushBytes)
      vkCmdPushConstants(cb, layout_, VK_SHADER_STAGE_VERTEX_BIT, 0, stages_.pushBytes, v.push);
    if (triangleCount) vkCmdDraw(cb, triangleCount * 3u, 1, 0, 0);
  }
  vkCmdEndRenderPass(cb);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {width, height, 1};
  vkCmdCopyImageToBuffer(cb, target_->id.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, out.handle(),
                         1, &region);
  region.bufferOffset = std::size_t(width) * height * 4;
  vkCmdCopyImageToBuffer(cb, target_->bary.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                         out.handle(), 1, &region);
}

}  // namespace sdfstream
