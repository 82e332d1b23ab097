// An engine that owns its Vulkan instance and device and hosts sdfstream's GI in its own frame:
// each frame it records the GI (streamed bricks, moving-object lists, light cache, probe passes)
// and then its own shading pass, which reads the probes through the installed GLSL include, into
// one command buffer, and submits it once. Two frames in flight, each with its own command
// buffer, fence and descriptor set; sdfstream never waits inside the loop.
//   embed_example WORLD OUT_DIR [--frames N] [--settle]
// --settle waits for the tile loader after each stack update (reproducible output for the test;
// a real engine never waits on disk). Writes OUT_DIR/irradiance.pfm (linear RGB floats).
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "gi/gi_system.h"
#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "streaming/tile_loader.h"

namespace {
constexpr std::uint32_t kSize = 64, kFramesInFlight = 2;
void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed");
}
std::vector<char> readFile(const char* path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// The engine's compute pass and its per-frame descriptor sets.
struct ShadingPass {
  VkDescriptorSetLayout setLayout;
  VkPipelineLayout layout;
  VkShaderModule module;
  VkPipeline pipeline;
  VkDescriptorPool descriptorPool;
  VkDescriptorSet sets[kFramesInFlight];
};

ShadingPass createShadingPass(VkDevice device) {
  ShadingPass p;
  std::vector<VkDescriptorSetLayoutBinding> slots(9);
  for (std::uint32_t b = 0; b < 9; ++b)
    slots[b] = {b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, nullptr, 0, 9, slots.data()};
  check(vkCreateDescriptorSetLayout(device, &li, nullptr, &p.setLayout), "set layout");
  VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, 32};
  VkPipelineLayoutCreateInfo pli{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, nullptr, 0, 1, &p.setLayout, 1, &push};
  check(vkCreatePipelineLayout(device, &pli, nullptr, &p.layout), "pipeline layout");
  const std::vector<char> spirv = readFile(EMBED_SHADER);
  VkShaderModuleCreateInfo si{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO, nullptr, 0, spirv.size(),
                              reinterpret_cast<const std::uint32_t*>(spirv.data())};
  check(vkCreateShaderModule(device, &si, nullptr, &p.module), "shader module");
  VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_COMPUTE_BIT, p.module, "main", nullptr};
  ci.layout = p.layout;
  check(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p.pipeline), "pipeline");
  VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 9 * kFramesInFlight};
  VkDescriptorPoolCreateInfo dpi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, nullptr, 0, kFramesInFlight, 1, &ps};
  check(vkCreateDescriptorPool(device, &dpi, nullptr, &p.descriptorPool), "descriptor pool");
  VkDescriptorSetLayout setLayouts[kFramesInFlight] = {p.setLayout, p.setLayout};
  VkDescriptorSetAllocateInfo dsi{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO, nullptr, p.descriptorPool, kFramesInFlight, setLayouts};
  check(vkAllocateDescriptorSets(device, &dsi, p.sets), "descriptor sets");
  return p;
}

void destroy(VkDevice device, const ShadingPass& p) {
  vkDestroyDescriptorPool(device, p.descriptorPool, nullptr);
  vkDestroyPipeline(device, p.pipeline, nullptr);
  vkDestroyShaderModule(device, p.module, nullptr);
  vkDestroyPipelineLayout(device, p.layout, nullptr);
  vkDestroyDescriptorSetLayout(device, p.setLayout, nullptr);
}

void writePfm(const std::string& path, const float* rgba) {
  std::ofstream out(path, std::ios::binary);
  out << "PF\n" << kSize << " " << kSize << "\n-1.0\n";
  for (std::uint32_t i = 0; i < kSize * kSize; ++i) out.write(reinterpret_cast<const char*>(rgba + 4 * i), 12);
}
}  // namespace

int main(int argc, char** argv) try {
  if (argc < 3) return std::fprintf(stderr, "usage: embed_example WORLD OUT_DIR [--frames N] [--settle]\n"), 2;
  int frames = 100;
  bool settle = false;
  for (int i = 3; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--frames") && i + 1 < argc) frames = std::stoi(argv[++i]);
    if (!std::strcmp(argv[i], "--settle")) settle = true;
  }
  // 1. The engine's Vulkan objects (validation on, so sdfstream can count its messages).
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO, nullptr, "embed", 1, "embed", 1, VK_API_VERSION_1_2};
  const char* layer = "VK_LAYER_KHRONOS_validation";
  const char* debugUtils = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
  VkInstanceCreateInfo ii{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, nullptr, 0, &app, 1, &layer, 1, &debugUtils};
  VkInstance instance;
  check(vkCreateInstance(&ii, nullptr, &instance), "vkCreateInstance");
  std::uint32_t count = 1;
  VkPhysicalDevice gpu;
  vkEnumeratePhysicalDevices(instance, &count, &gpu);
  const std::uint32_t family = 0;  // lavapipe and every desktop GPU: family 0 has compute
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qi{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO, nullptr, 0, family, 1, &priority};
  VkPhysicalDeviceVulkan12Features f12 = sdfstream::gpu::Context::requiredVulkan12Features();
  const auto extensions = sdfstream::gpu::Context::requiredDeviceExtensions();
  VkDeviceCreateInfo di{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f12, 0, 1, &qi, 0, nullptr,
                        std::uint32_t(extensions.size()), extensions.data(), nullptr};
  VkDevice device;
  check(vkCreateDevice(gpu, &di, nullptr, &device), "vkCreateDevice");
  VkQueue queue;
  vkGetDeviceQueue(device, family, 0, &queue);
  VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO, nullptr,
                             VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, family};
  VkCommandPool pool;
  check(vkCreateCommandPool(device, &pi, nullptr, &pool), "vkCreateCommandPool");
  VkCommandBuffer cbs[kFramesInFlight];
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr, pool,
                                 VK_COMMAND_BUFFER_LEVEL_PRIMARY, kFramesInFlight};
  check(vkAllocateCommandBuffers(device, &ai, cbs), "vkAllocateCommandBuffers");
  VkFence fences[kFramesInFlight];
  VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO, nullptr, VK_FENCE_CREATE_SIGNALED_BIT};
  for (VkFence& f : fences) check(vkCreateFence(device, &fi, nullptr, &f), "vkCreateFence");

  std::uint64_t submissions = 0, validationMessages = 0;
  {
    // 2. sdfstream on the engine's device, a streamed world and its GI.
    sdfstream::gpu::AdoptedDevice adopted{instance, gpu, device, family, 0, extensions, f12, true};
    sdfstream::gpu::ContextOptions options;
    options.validation = true;  // counted through a messenger on the engine's instance
    auto ctx = sdfstream::gpu::Context::adopt(adopted, options);
    sdfstream::PackTileStore store(argv[1]);
    sdfstream::TileLoader loader(store);
    sdfstream::StreamingOptions so;
    so.cascades = 3;
    sdfstream::CascadeStack stack(store, loader, so);
    sdfstream::GiSettings settings;  // a small probe budget: seconds on a CPU Vulkan device
    settings.probes.spacingBricks = 2;
    settings.probes.raysPerProbe = 64;
    settings.framesInFlight = kFramesInFlight;
    sdfstream::GiSystem gi(*ctx, settings, std::uint32_t(so.cascades));
    sdfstream::SceneLights lights;
    lights.lights.push_back({});  // the default: a sun straight down
    lights.lights[0].direction = glm::normalize(glm::vec3(0.4f, -1.0f, 0.3f));
    lights.lights[0].intensity = 3.0f;
    lights.sky.zenith = lights.sky.horizon = glm::vec3(0.3f, 0.4f, 0.6f);

    // 3. The engine's shading pass: sdfstream's buffers at bindings 0-7, its output at 8.
    const ShadingPass pass = createShadingPass(device);
    // The output: sdfstream's buffer class serves the engine too (host-visible, read at the end).
    sdfstream::gpu::Buffer pixels(*ctx, kSize * kSize * 16, sdfstream::gpu::BufferKind::Readback);

    // 4. The frame loop: record GI + shading into one command buffer, submit once.
    const std::uint64_t ownSubmitsBefore = ctx->submitCount(), waitsBefore = ctx->hostWaitCount();
    sdfstream::gpu::SubmitSignal slotSignal[kFramesInFlight] = {};
    for (int f = 0; f < frames; ++f) {
      const glm::dvec3 camera(0.3 + 0.004 * f, 0.4, 1.4 - 0.003 * f);
      stack.update(camera);
      if (settle) loader.waitIdle();
      const std::vector<std::uint32_t> dirty = stack.takeDirtySlots();
      const std::uint32_t slot = std::uint32_t(f) % kFramesInFlight;
      // The engine's own waits for the frame that last used this slot: its fence (the command
      // buffer is free), and sdfstream's timeline value of that frame, which the fence may
      // precede by a moment on some drivers (sdfstream then sees the slot's staging free too).
      vkWaitForFences(device, 1, &fences[slot], VK_TRUE, UINT64_MAX);
      if (slotSignal[slot].semaphore) {
        VkSemaphoreWaitInfo wi{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO, nullptr, 0, 1, &slotSignal[slot].semaphore, &slotSignal[slot].value};
        vkWaitSemaphores(device, &wi, UINT64_MAX);
      }
      vkResetFences(device, 1, &fences[slot]);
      VkCommandBuffer cb = cbs[slot];
      vkResetCommandBuffer(cb, 0);
      VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO, nullptr, VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
      vkBeginCommandBuffer(cb, &begin);
      sdfstream::probe::ProbeFrameInputs inputs;
      inputs.cameraWorld = camera;
      const sdfstream::GiFrameRecording rec = gi.record(cb, stack, dirty, lights, inputs, std::uint64_t(f));

      std::vector<VkDescriptorBufferInfo> infos(9);
      const auto probeBuffers = gi.sampleBindings();  // may change when buffers grow: every frame
      std::copy(probeBuffers.begin(), probeBuffers.end(), infos.begin());
      infos[8] = {pixels.handle(), 0, VK_WHOLE_SIZE};
      std::vector<VkWriteDescriptorSet> writes(9);
      for (std::uint32_t b = 0; b < 9; ++b)
        writes[b] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, nullptr, pass.sets[slot], b, 0, 1,
                     VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, nullptr, &infos[b], nullptr};
      vkUpdateDescriptorSets(device, 9, writes.data(), 0, nullptr);
      // The grid: 64 x 64 points 2 cm apart on the plane y = 0.15 m, in probe-field coordinates.
      const sdfstream::CascadeStackImage image = stack.stackImage();
      const glm::vec3 origin = image.toStack(glm::dvec3(-0.35, 0.15, -0.35));
      const struct {
        glm::vec4 originStep;
        glm::uvec4 size;
      } pc{glm::vec4(origin, float(0.02 / image.voxelSize0)), glm::uvec4(kSize, kSize, 0, 0)};
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pass.pipeline);
      vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pass.layout, 0, 1, &pass.sets[slot], 0, nullptr);
      vkCmdPushConstants(cb, pass.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
      vkCmdDispatch(cb, kSize * kSize / 64, 1, 1);
      vkEndCommandBuffer(cb);
      VkTimelineSemaphoreSubmitInfo ti{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO, nullptr, 0, nullptr, 1, &rec.signal.value};
      VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO, &ti, 0, nullptr, nullptr, 1, &cb, 1, &rec.signal.semaphore};
      check(vkQueueSubmit(queue, 1, &submit, fences[slot]), "vkQueueSubmit");
      slotSignal[slot] = rec.signal;
      ++submissions;
    }
    const std::uint64_t ownSubmits = ctx->submitCount() - ownSubmitsBefore, waits = ctx->hostWaitCount() - waitsBefore;
    vkDeviceWaitIdle(device);
    std::printf("embed: %d frames, %llu engine submissions, %llu by sdfstream, %llu sdfstream waits in the loop\n", frames,
                (unsigned long long)submissions, (unsigned long long)ownSubmits, (unsigned long long)waits);
    if (ownSubmits != 0 || waits != 0 || submissions != std::uint64_t(frames)) return 1;
    writePfm(std::string(argv[2]) + "/irradiance.pfm", static_cast<const float*>(pixels.mapped()));
    validationMessages = ctx->validationMessageCount();
    destroy(device, pass);
  }  // sdfstream goes first: the engine's device must outlive it
  for (VkFence f : fences) vkDestroyFence(device, f, nullptr);
  vkDestroyCommandPool(device, pool, nullptr);
  vkDestroyDevice(device, nullptr);
  vkDestroyInstance(instance, nullptr);
  std::printf("embed: %llu validation messages\n", (unsigned long long)validationMessages);
  return validationMessages == 0 ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "embed_example: %s\n", e.what());
  return 1;
}
