// The GI core in one object: the stack's device copy (GpuStackScene), the static
// voxel light cache (LightCache) and the probe field (ProbeField), driven once per frame in the
// order they depend on each other: sync the streamed bricks -> region lists of moving objects ->
// relight the dirty pages -> update the probes. Then irradiance(x, n, view) queries for shading.
//
// Two ways to run a frame:
//  - record(): everything (uploads through a staging ring of framesInFlight slots, region
//    lists, light cache, every probe pass) goes into the caller's command buffer with the
//    barriers it needs and no CPU wait; the caller submits it, signalling the returned timeline
//    value. Statistics and GPU timings come back a frame or more late (completedStats()).
//  - update(): the same recorded into an own batch, submitted and waited for (tests, the CLI).
// Both record identical commands, so their results are bit for bit the same.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "gi/gi_host_times.h"
#include "gi/gpu_stack_scene.h"
#include "gi/light_cache.h"
#include "gi/light_drift.h"
#include "gi/object_scene.h"
#include "gi/probe_field.h"
#include "gi/scene_lights.h"
#include "gpu/context.h"
#include "gpu/staging_ring.h"
#include "streaming/cascade_stack.h"

namespace sdfstream {

struct GiSettings {
  probe::ProbeFieldSettings probes;
  LightCacheSettings light;
  ObjectSceneSettings objects;
  // Frames record() may run ahead of the GPU; each owns its staging and readback memory.
  std::uint32_t framesInFlight = 2;
  // Frames after a light switch (not a drift), the first frame's lights included, that run
  // lightSwitchUpdatesPerFrame probe updates instead of one: each update adds one bounce of the
  // new light, so an interior whose light is mostly multi-bounce recovers sooner (a new field
  // too: the Breakfast Room's reads E/E_ref 0.94 after 8 frames with it, 0.85 without), for the
  // extra updates' GPU time in each (all updates are in GiFrameStats::passes; GiFrameStats::probes
  // counts the last). The updates take the hit-cache rotations in turn, and vigilant probes
  // blend at ProbeFieldSettings::lightSwitchHysteresis in these frames; the switch's vigilance
  // (lightSwitchVigilantUpdates, 18 = 6 x 3) ends with them. A paused field's catch-up waits
  // until it runs again.
  std::uint32_t lightSwitchCatchUpFrames = 6;
  std::uint32_t lightSwitchUpdatesPerFrame = 3;
  // Keep the atlas's distances by trilinear cell as well (GpuStackScene, "Corner atlas"): every
  // tracing pass but sampling (whose code it slowed) then reads a sample in one load instead of
  // 8, for 8 KiB of device memory per atlas slot beside the slot's 5.5 KiB (distances, albedo,
  // emission), where the device can bind it. Off: the passes read the distance atlas; results
  // are the same to the bit.
  bool cellCorners = true;
};

struct GiFrameStats {
  std::uint64_t frame = 0;  // as passed to update()/record()
  std::uint32_t pagesRelit = 0;
  double lightMilliseconds = 0.0;   // GPU time of the light cache pass (0 when skipped)
  double probeMilliseconds = 0.0;   // GPU time of all probe passes
  double objectMilliseconds = 0.0;  // GPU time of the macro-region passes (0 without objects)
  std::uint32_t objectInstances = 0;
  std::uint32_t objectPagesRelit = 0;  // light-cache pages objects' moves put out of date
  LightRelightStats relight;           // the light cache's queue after this frame's relight
  std::size_t bytesUploaded = 0;       // staging bytes of the frame (bricks, tables, instances)
  GiHostTimes host;
  probe::ProbeFieldStats probes;        // all zero when the probes were paused
  bool probesPaused = false;            // ProbeFrameInputs::paused
  std::vector<gpu::PassTiming> passes;  // every timed pass of the frame, in recording order
};

// What the caller's vkQueueSubmit of a recorded frame must signal (one
// VkTimelineSemaphoreSubmitInfo entry), on a queue of Context::queueFamily().
struct GiFrameRecording {
  gpu::SubmitSignal signal;
  std::uint64_t frame = 0;
};

class GiSystem {
 public:
  GiSystem(gpu::Context& context, const GiSettings& settings, std::uint32_t cascades);
  ~GiSystem();

  // One frame of a streaming stack: uploads its page tables and the atlas slots it rewrote
  // (CascadeStack::takeDirtySlots), relights dirty pages, updates the probes. Blocking.
  GiFrameStats update(const CascadeStack& stack, std::span<const std::uint32_t> dirtySlots,
                      const SceneLights& lights, probe::ProbeFrameInputs inputs,
                      std::uint64_t frame);
  // The same for a stack image that is uploaded whole (hand-built or static scenes).
  GiFrameStats update(const CascadeStackImage& image, const SceneLights& lights,
                      probe::ProbeFrameInputs inputs, std::uint64_t frame);

  // The same frames recorded into `commandBuffer` (begun by the caller, from a pool of
  // Context::queueFamily(), outside a render pass). Contract: the caller submits it, signalling
  // the returned value, before its next call into this GiSystem or its Context; commands it
  // records after ours see our results (the recording ends with a full barrier). Blocks only
  // when more than framesInFlight recorded frames are still running on the GPU.
  GiFrameRecording record(VkCommandBuffer commandBuffer, const CascadeStack& stack,
                          std::span<const std::uint32_t> dirtySlots, const SceneLights& lights,
                          probe::ProbeFrameInputs inputs, std::uint64_t frame);
  GiFrameRecording record(VkCommandBuffer commandBuffer, const CascadeStackImage& image,
                          const SceneLights& lights, probe::ProbeFrameInputs inputs,
                          std::uint64_t frame);
  // Statistics of the newest recorded frame the GPU has finished since the last call (older
  // finished frames are skipped); nullopt when none finished. Never waits.
  std::optional<GiFrameStats> completedStats();
  std::uint32_t framesInFlight() const { return staging_.framesInFlight(); }

  // Moving objects, or none (nullptr, the default). Each update then uploads the
  // instances, rebuilds the macro-region lists, relights the pages their moves shadow or
  // unshadow, traces them in the probe update, and consumes the set's change record
  // (instances->endFrame()). Both must outlive their use here. The library's meshes get their
  // cards captured (one GPU submission and wait per mesh) here when
  // settings.objects.cardTexelWorld is set, else at the start of the first frame, before its
  // commands are recorded; meshes added later at the start of the next frame.
  void setObjects(const ObjectLibrary* library, InstanceSet* instances);
  const ObjectScene& objects() const { return objects_; }
  ObjectScene& objects() { return objects_; }

  // irradiance(x, n, view) of the current probes (cascade-0 voxels of the last frame's stack).
  // Blocking (a CPU round trip): engines sample in their own shaders instead. Queries in pixel
  // tiles run fastest (ProbeField::sample).
  std::vector<glm::vec3> irradiance(std::span<const gpu_shared::ProbeQuery> queries);
  // The same for an image of queries (width × height, row by row; zero normal: no surface),
  // sampled at one pixel per blockSize × blockSize block (2: half resolution, 4: quarter) and
  // upsampled (ProbeField::sampleHalfResolution).
  std::vector<glm::vec3> irradianceHalfResolution(std::span<const gpu_shared::ProbeQuery> image,
                                                  std::uint32_t width, std::uint32_t height,
                                                  std::uint32_t blockSize = 2);
  double lastSampleMilliseconds() const;
  // What an engine binds to sample the probes in its own shader (sdfstream/probe_sample.glsl),
  // in binding order from SDFSTREAM_PROBE_BINDING: probe frame constants, volumes, probe data,
  // irradiance, depth, then the stack's page tables, distance atlas and cascade params (SDF
  // visibility). Valid for commands recorded after record()/update() of a frame and until the
  // next one (buffers may be replaced when the streamed atlas grows): query it every frame.
  static constexpr std::size_t kSampleBindingCount = 8;
  std::array<VkDescriptorBufferInfo, kSampleBindingCount> sampleBindings() const;
  // The same buffers, for a pass of this library's own (CommandBatch::dispatch).
  std::array<const gpu::Buffer*, kSampleBindingCount> sampleBuffers() const;

  const GpuStackScene& scene() const { return scene_; }
  // GpuStackScene::reserveAtlas with the probe field's bounce cells for as many slots (8 bytes
  // a material voxel): the atlas slots the device could hold together with them, at most `slots`.
  std::uint32_t reserveAtlasSlots(std::uint32_t slots);
  // GpuStackScene::shrinkAtlas (and the bounce cells with it), after a frame ran out of device
  // memory (nothing is in flight: frames of update() are blocking).
  std::uint32_t shrinkAtlasSlots(std::uint32_t slots);
  const LightCache& lightCache() const { return light_; }
  // Light-cache pages relit per frame from the next frame on (LightCacheSettings).
  void setRelightPageBudget(std::uint32_t pages) { relight_.setPageBudget(pages); }
  const probe::ProbeField& probes() const { return probes_; }
  probe::ProbeField& probes() { return probes_; }
  const CascadeStackImage* lastImage() const { return previous_.get(); }

 private:
  struct FrameInFlight {
    gpu::CommandBatch batch;
    std::uint32_t slot = 0;
    GiFrameStats stats;  // the host-side part, filled at record time
  };
  // Uploads the scene (whole image or streamed slots) into the frame's batch.
  using SceneUpload = std::function<std::size_t(gpu::CommandBatch&, gpu::StagingRing&)>;
  GiFrameStats recordFrame(gpu::CommandBatch& batch, const SceneUpload& upload,
                           const CascadeStackImage& image, const SceneLights& lights,
                           probe::ProbeFrameInputs inputs, std::uint64_t frame);
  GiFrameStats runBlocking(const SceneUpload& upload, const CascadeStackImage& image,
                           const SceneLights& lights, probe::ProbeFrameInputs inputs,
                           std::uint64_t frame);
  GiFrameRecording runRecorded(VkCommandBuffer commandBuffer, const SceneUpload& upload,
                               const CascadeStackImage& image, const SceneLights& lights,
                               probe::ProbeFrameInputs inputs, std::uint64_t frame);
  // Completes a finished frame's statistics (GPU timings, probe counters) and makes them what
  // the parts' lastTimings()/lastStats() report.
  GiFrameStats harvest(FrameInFlight& done);
  std::uint32_t lightSwitchVigilance() const;  // ProbeFrameInputs::lightSwitchVigilantUpdates
  void harvestCompleted();

  gpu::Context& context_;
  GpuStackScene scene_;
  LightCache light_;
  probe::ProbeField probes_;
  ObjectScene objects_;
  gpu::StagingRing staging_;
  const ObjectLibrary* objectLibrary_ = nullptr;
  InstanceSet* instances_ = nullptr;
  std::unique_ptr<CascadeStackImage> previous_;
  LightRelightQueue relight_;
  std::uint64_t lightsVersion_ = ~std::uint64_t(0);
  const std::uint32_t lightSwitchCatchUpFrames_;
  const std::uint32_t catchUpUpdatesPerFrame_;
  const std::uint32_t framePasses_;     // timed passes a frame's batch has room for
  const std::uint32_t probeListCapacity_;      // probes one update's list holds
  const std::uint32_t switchVigilantUpdates_;  // a switch's vigilance where every probe fits
  const std::uint32_t vigilantMeanUpdates_;
  std::uint32_t catchUpFramesLeft_ = 0;  // catch-up frames (several probe updates) still to run
  std::size_t lightCount_ = 0;
  SceneLights lastLights_;  // the previous frame's, to tell a drift from a change
  LightDriftLimits lightDrift_;
  std::deque<FrameInFlight> inFlight_;
  std::optional<GiFrameStats> completed_;
};

}  // namespace sdfstream
