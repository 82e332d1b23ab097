#include "gi/gi_system.h"

#include <algorithm>
#include <chrono>
#include <string_view>
#include <utility>

#include "core/stopwatch.h"

namespace sdfstream {
namespace {
// Timed passes per frame: 3 region passes, the light cache, 7 probe passes, with room to spare.
constexpr std::uint32_t kFramePasses = 16;

std::vector<gpu::PassTiming> passesStartingWith(const std::vector<gpu::PassTiming>& all,
                                                std::string_view prefix) {
  std::vector<gpu::PassTiming> out;
  for (const gpu::PassTiming& t : all)
    if (std::string_view(t.name).starts_with(prefix)) out.push_back(t);
  return out;
}

double totalMilliseconds(const std::vector<gpu::PassTiming>& passes) {
  double ms = 0.0;
  for (const gpu::PassTiming& t : passes) ms += t.milliseconds;
  return ms;
}
}  // namespace

GiSystem::GiSystem(gpu::Context& context, const GiSettings& settings, std::uint32_t cascades)
    : context_(context),
      scene_(context),
      light_(context, settings.light),
      probes_(context, settings.probes, cascades),
      objects_(context, settings.objects),
      staging_(context, std::max(1u, settings.framesInFlight)),
      relight_(settings.light.relightPageBudget),
      lightSwitchCatchUpFrames_(settings.lightSwitchCatchUpFrames),
      lightDrift_{settings.probes.lightDriftDegrees, settings.probes.lightDriftIntensity} {}

// Frames still in flight keep their batches (query pools) alive until the GPU is done with them:
// CommandBatch's destruction is deferred like every other GPU object's.
GiSystem::~GiSystem() = default;

void GiSystem::setObjects(const ObjectLibrary* library, InstanceSet* instances) {
  objectLibrary_ = library;
  instances_ = library ? instances : nullptr;
  probes_.setObjects(instances_ ? &objects_ : nullptr);
  if (instances_) objects_.prepareCards(*library);  // now only with a fixed cardTexelWorld
}

GiFrameStats GiSystem::update(const CascadeStack& stack, std::span<const std::uint32_t> dirtySlots,
                              const SceneLights& lights, probe::ProbeFrameInputs inputs,
                              std::uint64_t frame) {
  return runBlocking(
      [&](gpu::CommandBatch& b, gpu::StagingRing& s) {
        return scene_.recordSync(b, s, stack, dirtySlots);
      },
      stack.stackImage(), lights, inputs, frame);
}

GiFrameStats GiSystem::update(const CascadeStackImage& image, const SceneLights& lights,
                              probe::ProbeFrameInputs inputs, std::uint64_t frame) {
  return runBlocking([&](gpu::CommandBatch& b,
                         gpu::StagingRing& s) { return scene_.recordUploadAll(b, s, image); },
                     image, lights, inputs, frame);
}

GiFrameRecording GiSystem::record(VkCommandBuffer commandBuffer, const CascadeStack& stack,
                                  std::span<const std::uint32_t> dirtySlots,
                                  const SceneLights& lights, probe::ProbeFrameInputs inputs,
                                  std::uint64_t frame) {
  return runRecorded(
      commandBuffer,
      [&](gpu::CommandBatch& b, gpu::StagingRing& s) {
        return scene_.recordSync(b, s, stack, dirtySlots);
      },
      stack.stackImage(), lights, inputs, frame);
}

GiFrameRecording GiSystem::record(VkCommandBuffer commandBuffer, const CascadeStackImage& image,
                                  const SceneLights& lights, probe::ProbeFrameInputs inputs,
                                  std::uint64_t frame) {
  return runRecorded(
      commandBuffer,
      [&](gpu::CommandBatch& b, gpu::StagingRing& s) {
        return scene_.recordUploadAll(b, s, image);
      },
      image, lights, inputs, frame);
}

GiFrameStats GiSystem::runBlocking(const SceneUpload& upload, const CascadeStackImage& image,
                                   const SceneLights& lights, probe::ProbeFrameInputs inputs,
                                   std::uint64_t frame) {
  // Before the frame's batch opens.
  if (instances_) objects_.prepareCards(*objectLibrary_, image.voxelSize0);
  staging_.beginFrame();
  harvestCompleted();
  FrameInFlight f{context_.beginBatch(kFramePasses), staging_.currentSlot(), {}};
  f.stats = recordFrame(f.batch, upload, image, lights, inputs, frame);
  staging_.endFrame(f.batch.submit());
  f.batch.wait();
  return harvest(f);
}

GiFrameRecording GiSystem::runRecorded(VkCommandBuffer commandBuffer, const SceneUpload& upload,
                                       const CascadeStackImage& image, const SceneLights& lights,
                                       probe::ProbeFrameInputs inputs, std::uint64_t frame) {
  // New meshes' cards are captured with a submission of our own (at load time, not per frame).
  if (instances_) objects_.prepareCards(*objectLibrary_, image.voxelSize0);
  staging_.beginFrame();  // waits only when the slot's earlier frame is still running
  harvestCompleted();     // before this frame's copies overwrite the slot's readback
  FrameInFlight f{context_.recordInto(commandBuffer, kFramePasses), staging_.currentSlot(), {}};
  f.stats = recordFrame(f.batch, upload, image, lights, inputs, frame);
  const gpu::SubmitSignal signal = f.batch.finish();
  staging_.endFrame(signal.value);
  inFlight_.push_back(std::move(f));
  return {signal, frame};
}

GiFrameStats GiSystem::recordFrame(gpu::CommandBatch& batch, const SceneUpload& upload,
                                   const CascadeStackImage& image, const SceneLights& lights,
                                   probe::ProbeFrameInputs inputs, std::uint64_t frame) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  GiFrameStats stats;
  stats.frame = frame;
  upload(batch, staging_);
  stats.host.sceneMs = millisecondsSince(start);
  Clock::time_point t = Clock::now();
  // Lights are world-fixed: the light cache (radiance per voxel) only changes when they do,
  // not when cascade 0 moves and their cascade-relative GPU form with it.
  const bool lightsChanged =
      lights.version != lightsVersion_ || lights.lights.size() != lightCount_;
  // A small change (a sun turning a fraction of a degree a frame) is a drift for the probes: the
  // light cache and the cards still relight (within their budgets), but no probe wakes.
  const bool firstLights = lightsVersion_ == ~std::uint64_t(0);
  const bool lightsDrifted =
      lightsChanged && !firstLights && isLightDrift(lastLights_, lights, lightDrift_);
  if (lightsChanged && !firstLights && !lightsDrifted)
    catchUpFramesLeft_ = lightSwitchCatchUpFrames_;
  if (lightsChanged) lastLights_ = lights;
  lightsVersion_ = lights.version;
  lightCount_ = lights.lights.size();
  const std::vector<std::uint32_t> changed = lightDirtyPages(previous_.get(), image, false);
  const auto gpuLights = toGpu(lights.lights, image);
  const gpu_shared::GpuSky sky = toGpu(lights.sky);
  stats.host.lightMs = millisecondsSince(t);
  std::vector<std::uint32_t> shadowed;
  if (instances_) {
    t = Clock::now();
    objects_.record(batch, staging_, *objectLibrary_, *instances_, image, lightsChanged);
    stats.objectInstances = std::uint32_t(instances_->size());
    stats.host.objectsMs = millisecondsSince(t);
    stats.host.objectsBuildMs = objects_.lastBuildMilliseconds();
    stats.host.objectsInstancesMs = objects_.frame().instancesMs;
    stats.host.objectsWakeMs = objects_.frame().wakeMs;
    stats.host.objectsCardsMs = objects_.lastCardsMilliseconds();
    t = Clock::now();
    // Only where objects moved: the pages their old and new poses shadow.
    shadowed = objectShadowPages(image, objects_.frame().changedBoxes, gpuLights);
    stats.objectPagesRelit = std::uint32_t(shadowed.size());
    instances_->endFrame();
    stats.host.shadowPagesMs = millisecondsSince(t);
  }
  t = Clock::now();
  const std::vector<std::uint32_t> dirty = relight_.select(image, changed, shadowed, lightsChanged);
  stats.relight = relight_.stats();
  light_.record(batch, staging_, scene_, gpuLights, sky, dirty, image.voxelSize0,
                instances_ ? &objects_ : nullptr);
  stats.host.lightMs += millisecondsSince(t);
  t = Clock::now();
  inputs.sky = sky;
  inputs.lightsChanged = inputs.lightsChanged || (lightsChanged && !lightsDrifted);
  inputs.lightsDrifting = inputs.lightsDrifting || lightsDrifted;
  stats.probesPaused = inputs.paused;
  if (!inputs.paused) {
    probes_.record(batch, staging_, scene_, image, light_.radianceBuffer(), inputs, frame);
    if (catchUpFramesLeft_ > 0) {
      // The same frame again (same rays, same probes): one more bounce of the new light.
      --catchUpFramesLeft_;
      probe::ProbeFrameInputs again = inputs;
      again.lightsChanged = false;
      probes_.record(batch, staging_, scene_, image, light_.radianceBuffer(), again, frame);
    }
  }
  stats.pagesRelit = light_.pagesRelitLastUpdate();
  stats.bytesUploaded = staging_.bytesThisFrame();
  previous_ = std::make_unique<CascadeStackImage>(image);
  stats.host.probesMs = millisecondsSince(t);
  stats.host.totalMs = millisecondsSince(start);
  return stats;
}

GiFrameStats GiSystem::harvest(FrameInFlight& done) {
  GiFrameStats stats = std::move(done.stats);
  stats.passes = done.batch.timings();
  if (!stats.probesPaused) stats.probes = probes_.readStats(done.slot);
  light_.timings_ = passesStartingWith(stats.passes, "light_cache");
  objects_.timings_ = passesStartingWith(stats.passes, "object_regions");
  probes_.timings_ = passesStartingWith(stats.passes, "probe_");
  probes_.stats_ = stats.probes;
  stats.lightMilliseconds = totalMilliseconds(light_.timings_);
  stats.objectMilliseconds = totalMilliseconds(objects_.timings_);
  stats.probeMilliseconds = totalMilliseconds(probes_.timings_);
  return stats;
}

void GiSystem::harvestCompleted() {
  while (!inFlight_.empty() && inFlight_.front().batch.completed()) {
    completed_ = harvest(inFlight_.front());
    inFlight_.pop_front();
  }
}

std::optional<GiFrameStats> GiSystem::completedStats() {
  harvestCompleted();
  return std::exchange(completed_, std::nullopt);
}

std::vector<glm::vec3> GiSystem::irradiance(std::span<const gpu_shared::ProbeQuery> queries) {
  return probes_.sample(scene_, light_.radianceBuffer(), queries);
}

std::array<const gpu::Buffer*, GiSystem::kSampleBindingCount> GiSystem::sampleBuffers() const {
  const auto probe = probes_.sampleBuffers();
  return {probe[0],           probe[1],        probe[2], probe[3], probe[4], &scene_.pageTables(),
          &scene_.distance(), &scene_.params()};
}

std::array<VkDescriptorBufferInfo, GiSystem::kSampleBindingCount> GiSystem::sampleBindings() const {
  const auto buffers = sampleBuffers();
  std::array<VkDescriptorBufferInfo, kSampleBindingCount> out{};
  for (std::size_t i = 0; i < kSampleBindingCount; ++i)
    out[i] = {buffers[i]->handle(), 0, VK_WHOLE_SIZE};
  return out;
}

double GiSystem::lastSampleMilliseconds() const { return probes_.lastMilliseconds(); }

}  // namespace sdfstream
