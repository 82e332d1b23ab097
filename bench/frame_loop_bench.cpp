#include "bench/frame_loop_bench.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/atomic_dir.h"
#include "demo/fly_path.h"
#include "gi/gi_system.h"
#include "objects/scripted_motion.h"
#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "streaming/tile_loader.h"

namespace sdfstream::bench {
namespace {

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// The engine's part of the record mode: command buffers and fences of its own on sdfstream's
// device and queue.
class EngineFrames {
 public:
  EngineFrames(gpu::Context& ctx, std::uint32_t count) : ctx_(ctx) {
    VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = ctx.queueFamily();
    if (vkCreateCommandPool(ctx.device(), &pool, nullptr, &pool_) != VK_SUCCESS)
      throw std::runtime_error("vkCreateCommandPool failed");
    cbs_.resize(count);
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = pool_;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = count;
    vkAllocateCommandBuffers(ctx.device(), &alloc, cbs_.data());
    fences_.resize(count);
    signals_.resize(count);
    VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fence.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    for (VkFence& f : fences_) vkCreateFence(ctx.device(), &fence, nullptr, &f);
  }
  ~EngineFrames() {
    vkDeviceWaitIdle(ctx_.device());
    for (VkFence f : fences_) vkDestroyFence(ctx_.device(), f, nullptr);
    vkDestroyCommandPool(ctx_.device(), pool_, nullptr);
  }
  VkCommandBuffer begin(std::uint64_t frame) {
    slot_ = std::uint32_t(frame % cbs_.size());
    vkWaitForFences(ctx_.device(), 1, &fences_[slot_], VK_TRUE, UINT64_MAX);
    // Also sdfstream's timeline value of that frame: a fence may precede it by a moment.
    if (signals_[slot_].semaphore) {
      VkSemaphoreWaitInfo wi{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
      wi.semaphoreCount = 1;
      wi.pSemaphores = &signals_[slot_].semaphore;
      wi.pValues = &signals_[slot_].value;
      vkWaitSemaphores(ctx_.device(), &wi, UINT64_MAX);
    }
    vkResetFences(ctx_.device(), 1, &fences_[slot_]);
    vkResetCommandBuffer(cbs_[slot_], 0);
    VkCommandBufferBeginInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vkBeginCommandBuffer(cbs_[slot_], &info);
    return cbs_[slot_];
  }
  void submit(const gpu::SubmitSignal& signal) {
    VkCommandBuffer cb = cbs_[slot_];
    vkEndCommandBuffer(cb);
    VkTimelineSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
    timeline.signalSemaphoreValueCount = 1;
    timeline.pSignalSemaphoreValues = &signal.value;
    VkSubmitInfo info{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    info.pNext = &timeline;
    info.commandBufferCount = 1;
    info.pCommandBuffers = &cb;
    info.signalSemaphoreCount = 1;
    info.pSignalSemaphores = &signal.semaphore;
    if (vkQueueSubmit(ctx_.queue(), 1, &info, fences_[slot_]) != VK_SUCCESS)
      throw std::runtime_error("vkQueueSubmit failed");
    signals_[slot_] = signal;
  }

 private:
  gpu::Context& ctx_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  std::vector<VkCommandBuffer> cbs_;
  std::vector<VkFence> fences_;
  std::vector<gpu::SubmitSignal> signals_;
  std::uint32_t slot_ = 0;
};

struct ModeResult {
  std::string name;
  double wallSeconds = 0, cpuSeconds = 0, gpuMilliseconds = 0;
  std::uint64_t submitsBySdfstream = 0, waitsBySdfstream = 0;
  int frames = 0;
  double fps() const { return frames / wallSeconds; }
  double cpuMsPerFrame() const { return 1e3 * cpuSeconds / frames; }
};

// One mode from a fresh stack and GI: warm-up frames, then the measured ones.
ModeResult runMode(gpu::Context& ctx, const FrameLoopOptions& o, bool recorded) {
  PackTileStore store(o.world);
  TileLoader loader(store);
  StreamingOptions so;
  so.cascades = o.cascades;
  CascadeStack stack(store, loader, so);
  GiSettings settings;
  settings.framesInFlight = o.framesInFlight;
  GiSystem gi(ctx, settings, std::uint32_t(o.cascades));
  const PackManifest& m = store.manifest();
  const FlyPath path = defaultFlyPath(m.boundsMin, m.boundsMax);
  ObjectLibrary library;
  InstanceSet instances;
  const WorldBox area{m.boundsMin, m.boundsMax};
  const ScriptedMotion motion = spreadObjects(instances, library, o.objects, area, 1);
  if (o.objects > 0) gi.setObjects(&library, &instances);
  SceneLights lights;
  lights.lights.push_back({});
  lights.lights[0].direction = glm::normalize(glm::vec3(0.3f, -1.0f, 0.4f));
  lights.lights[0].intensity = 3.0f;
  lights.sky.zenith = glm::vec3(0.3f, 0.45f, 0.8f);
  lights.sky.horizon = glm::vec3(0.6f, 0.7f, 0.8f);
  std::unique_ptr<EngineFrames> engine;
  if (recorded) engine = std::make_unique<EngineFrames>(ctx, o.framesInFlight);

  ModeResult r;
  r.name = recorded ? "record, " + std::to_string(o.framesInFlight) + " frames in flight" : "blocking";
  r.frames = o.frames;
  std::uint64_t submits0 = 0, waits0 = 0;
  auto t0 = std::chrono::steady_clock::now();
  double cpu0 = 0;
  for (int f = 0; f < o.warmup + o.frames; ++f) {
    if (f == o.warmup) {
      t0 = std::chrono::steady_clock::now();
      cpu0 = threadCpuSeconds();
      submits0 = ctx.submitCount();
      waits0 = ctx.hostWaitCount();
    }
    const double s = std::fmod(o.speed * f / 60.0, path.length());
    const glm::dvec3 camera = path.position(s);
    stack.update(camera, path.direction(s));
    const std::vector<std::uint32_t> dirty = stack.takeDirtySlots();
    motion.apply(instances, f / 60.0);
    probe::ProbeFrameInputs inputs;
    inputs.cameraWorld = camera;
    inputs.viewDirection = glm::vec3(path.direction(s));
    if (recorded) {
      VkCommandBuffer cb = engine->begin(std::uint64_t(f));
      engine->submit(gi.record(cb, stack, dirty, lights, inputs, std::uint64_t(f)).signal);
      if (const auto st = gi.completedStats(); st && f >= o.warmup)
        r.gpuMilliseconds += st->lightMilliseconds + st->probeMilliseconds + st->objectMilliseconds;
    } else {
      const GiFrameStats st = gi.update(stack, dirty, lights, inputs, std::uint64_t(f));
      if (f >= o.warmup) r.gpuMilliseconds += st.lightMilliseconds + st.probeMilliseconds + st.objectMilliseconds;
    }
  }
  if (recorded) vkQueueWaitIdle(ctx.queue());  // the engine's end of the run, outside the loop
  r.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.cpuSeconds = threadCpuSeconds() - cpu0;
  r.submitsBySdfstream = ctx.submitCount() - submits0;
  r.waitsBySdfstream = ctx.hostWaitCount() - waits0;
  r.gpuMilliseconds /= o.frames;
  return r;
}

}  // namespace

void runFrameLoopBench(const FrameLoopOptions& o) {
  gpu::ContextOptions co;
  co.validation = o.validation;
  auto ctx = gpu::Context::create(co);
  std::printf("bench frames: %s, %d frames (+%d warm-up) per mode, %u objects, %d cascades\n",
              ctx->deviceName().c_str(), o.frames, o.warmup, o.objects, o.cascades);
  const ModeResult blocking = runMode(*ctx, o, false);
  const ModeResult recorded = runMode(*ctx, o, true);
  std::string md = "# Frames in flight vs blocking frames\n\nDevice: " + ctx->deviceName() +
                   "; world " + o.world.string() + "; " + std::to_string(o.frames) +
                   " measured frames per mode after " + std::to_string(o.warmup) +
                   " warm-up; " + std::to_string(o.objects) + " moving objects.\n\n" +
                   "| mode | frames/s | main-thread CPU ms/frame | GPU ms/frame (GI passes) | sdfstream submits | sdfstream waits |\n|---|---|---|---|---|---|\n";
  for (const ModeResult* r : {&blocking, &recorded}) {
    char line[256];
    std::snprintf(line, sizeof line, "| %s | %.1f | %.3f | %.3f | %llu | %llu |\n", r->name.c_str(),
                  r->fps(), r->cpuMsPerFrame(), r->gpuMilliseconds,
                  static_cast<unsigned long long>(r->submitsBySdfstream),
                  static_cast<unsigned long long>(r->waitsBySdfstream));
    md += line;
  }
  char ratio[160];
  std::snprintf(ratio, sizeof ratio, "\nframe rate ratio (record / blocking): %.2f; CPU time ratio: %.2f\n",
                recorded.fps() / blocking.fps(), recorded.cpuMsPerFrame() / blocking.cpuMsPerFrame());
  md += ratio;
  std::fputs(md.c_str(), stdout);
  std::filesystem::create_directories(o.out);
  writeFileAtomically(o.out / "summary.md", md.data(), md.size());
}

}  // namespace sdfstream::bench
