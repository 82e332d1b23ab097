#include "gi/gi_system.h"

#include <algorithm>
#include <chrono>
#include <string_view>
#include <utility>

#include "core/stopwatch.h"

namespace sdfstream {
namespace {
// Timed passes per frame: the atlas upload's, the region passes and the light cache's, then 7
// probe passes per probe update (a light switch's catch-up frames run several), each with room
// to spare.
constexpr std::uint32_t kPassesBesideProbes =
    GpuStackScene::kUploadPasses + ObjectScene::kRegionPasses + 6;
constexpr std::uint32_t kPassesPerProbeUpdate = 8;

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
      scene_(context, settings.cellCorners),
      light_(context, settings.light),
      probes_(context, settings.probes, cascades),
      objects_(context, settings.objects),
      staging_(context, std::max(1u, settings.framesInFlight)),
      relight_(settings.light.relightPageBudget),
      lightSwitchCatchUpFrames_(settings.lightSwitchCatchUpFrames),
      catchUpUpdatesPerFrame_(std::max(1u, settings.lightSwitchUpdatesPerFrame)),
      framePasses_(kPassesBesideProbes + kPassesPerProbeUpdate * catchUpUpdatesPerFrame_),
      probeListCapacity_(settings.probes.listCapacity(cascades)),
      switchVigilantUpdates_(settings.probes.switchVigilantUpdates()),
      vigilantMeanUpdates_(settings.probes.vigilantMeanUpdates),
      lightDrift_{settings.probes.lightDriftDegrees, settings.probes.lightDriftIntensity} {
  // Compiled here, not in the first frame: the corners are kept wherever they are wanted and fit.
  light_.preparePipelines(settings.cellCorners);
  probes_.preparePipelines(settings.cellCorners);
}

// A switch's vigilance in updates of each probe: as many as the catch-up gives a probe. Where
// more probes live than one update's list holds (Sponza's 4 cascades: ~2x), each update takes
// a share of them, and a probe still vigilant after the catch-up would blend its remaining
// updates at vigilantHysteresis, one rotation at a time, for as many frames again as its
// share takes (measured: Sponza's switch reached its closing mean only ~27 frames later). The
// live count is the last harvested frame's (a frame or two old: it changes slowly).
// The bounce cells take 8 bytes per material voxel, twice the light cache's: reserved with the
// atlas, so that a device without room for both keeps fewer slots (and says so) instead of
// failing in a frame. Where they do not fit, the atlas halves (GpuStackScene::shrinkAtlas,
// which throws at its floor) until they do.
std::uint32_t GiSystem::reserveAtlasSlots(std::uint32_t slots) {
  std::uint32_t got = scene_.reserveAtlas(slots);
  for (;;) {
    try {
      probes_.reserveBounceCells(got);
      return got;
    } catch (const gpu::OutOfDeviceMemory&) {
      got = scene_.shrinkAtlas(got / 2);
    }
  }
}

std::uint32_t GiSystem::shrinkAtlasSlots(std::uint32_t slots) {
  probes_.reserveBounceCells(0);  // their memory back before the atlas asks again
  return reserveAtlasSlots(scene_.shrinkAtlas(slots));
}

std::uint32_t GiSystem::lightSwitchVigilance() const {
  const probe::ProbeFieldStats& s = probes_.lastStats();
  namespace gs = gpu_shared;
  const std::uint64_t live = std::uint64_t(s.states[gs::kProbeSleeping]) +
                             s.states[gs::kProbeAwake] + s.states[gs::kProbeVigilant];
  const std::uint64_t updates = std::uint64_t(lightSwitchCatchUpFrames_) * catchUpUpdatesPerFrame_;
  std::uint64_t perProbe = switchVigilantUpdates_;
  if (updates > 0 && live > probeListCapacity_)
    perProbe = std::min<std::uint64_t>(perProbe, (updates * probeListCapacity_ + live - 1) / live);
  return std::uint32_t(std::max<std::uint64_t>(
      perProbe, std::min(switchVigilantUpdates_, vigilantMeanUpdates_ + 2u)));
}

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
  FrameInFlight f{context_.beginBatch(framePasses_), staging_.currentSlot(), {}};
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
  FrameInFlight f{context_.recordInto(commandBuffer, framePasses_), staging_.currentSlot(), {}};
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
  // The first lights too: a new field's bounces build up one an update, as after a switch.
  if (lightsChanged && !lightsDrifted) catchUpFramesLeft_ = lightSwitchCatchUpFrames_;
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
    // Only where objects moved: the pages their old and new poses shadow, found on a worker
    // thread while the objects' card slots and passes are recorded (it needs only the frame's
    // changed boxes), so the two share the cores instead of taking turns.
    auto findShadowedPages = [&] {
      const Clock::time_point own = Clock::now();
      shadowed = objectShadowPages(image, objects_.frame().changedBoxes, gpuLights);
      stats.host.shadowPagesMs = millisecondsSince(own);
    };
    objects_.record(batch, staging_, *objectLibrary_, *instances_, image, lightsChanged,
                    findShadowedPages);
    stats.objectPagesRelit = std::uint32_t(shadowed.size());
    instances_->endFrame();
    stats.objectInstances = std::uint32_t(instances_->size());
    stats.host.objectsMs = millisecondsSince(t);
    stats.host.objectsBuildMs = objects_.lastBuildMilliseconds();
    stats.host.objectsInstancesMs = objects_.frame().instancesMs;
    stats.host.objectsWakeMs = objects_.frame().wakeMs;
    stats.host.objectsCardsMs = objects_.lastCardsMilliseconds();
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
    // A catch-up frame runs its updates one after another (same probes), each one more bounce
    // of the new light, each through the probe's next hit-cache rotation (so any R updates of
    // a probe in a row see every rotation's directions). Update j of frame k counts as update
    // n k + j of the schedule, so where not every probe fits a list each takes other probes.
    const bool catchUp = catchUpFramesLeft_ > 0;
    const std::uint32_t switchVigilance = inputs.lightsChanged ? lightSwitchVigilance() : 0u;
    const std::uint32_t updates = catchUp ? catchUpUpdatesPerFrame_ : 1u;
    for (std::uint32_t j = 0; j < updates; ++j) {
      probe::ProbeFrameInputs in = inputs;
      in.lightSwitchCatchUp = catchUp;
      in.lightsChanged = inputs.lightsChanged && j == 0;
      in.lightSwitchVigilantUpdates = switchVigilance;
      if (catchUp) in.updateShift = std::uint32_t((updates - 1) * frame + j);
      probes_.record(batch, staging_, scene_, image, light_.radianceBuffer(), in, frame);
    }
    if (catchUp) --catchUpFramesLeft_;
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

std::vector<glm::vec3> GiSystem::irradianceHalfResolution(
    std::span<const gpu_shared::ProbeQuery> image, std::uint32_t width, std::uint32_t height,
    std::uint32_t blockSize) {
  return probes_.sampleHalfResolution(scene_, light_.radianceBuffer(), image, width, height,
                                      blockSize);
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
