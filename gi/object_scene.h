// Moving objects on the GPU: the object-SDF atlas (uploaded when the library changes), this
// frame's instances in stack space, and the macro-region object lists and their sub-cell lists
// rebuilt by object_regions.comp and object_regions_scan.comp (count -> rank -> scan -> sub-cell
// count -> sub-cell scan -> fill) every frame from the instances. Passes that
// trace objects bind buffers() at their OBJ_BINDING_BASE (shaders/object_bindings.glsl). With no
// instance at all nothing is dispatched (active() is false), so static-only frames cost exactly
// what they cost before objects existed. Cards (cards/): each mesh's card atlas, captured by
// prepareCards, and each instance's card light block (CardLightSlots), bound as object bindings
// 6 and 7 and relit by the light cache's card pass.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "cards/card_rasterizer.h"
#include "gi/card_light_slots.h"
#include "gi/object_frame.h"
#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "gpu/compute_pipeline.h"
#include "gpu/context.h"
#include "gpu/staging_ring.h"

namespace sdfstream {

class GiSystem;

// What passes that can trace objects bind when a frame has none: a zeroed meta buffer (zero
// instances, so the shaders read nothing else) and a tiny buffer for the other seven bindings.
class NoObjectsBindings {
 public:
  explicit NoObjectsBindings(gpu::Context& context);
  std::array<const gpu::Buffer*, 8> buffers() const {
    return {&meta_, &empty_, &empty_, &empty_, &empty_, &empty_, &empty_, &empty_};
  }

 private:
  gpu::Buffer meta_, empty_;
};

class ObjectScene {
 public:
  ObjectScene(gpu::Context& context, ObjectSceneSettings settings = {});

  // Rebuilds this frame's data: re-uploads the atlas when library.version() changed, uploads the
  // instances (poses relative to `stack`'s cascade 0) and runs the region passes. Blocking.
  // Call once per frame before the passes that trace objects, then instances.endFrame().
  void update(const ObjectLibrary& library, const InstanceSet& instances,
              const CascadeStackImage& stack);
  // Captures the cards of the library's meshes when it changed since the last call (a blocking
  // GPU submission of its own, so call it while no batch of this Context is recording: before a
  // frame's batch begins; GiSystem does). Card texels are about settings().cardTexelWorld world
  // units, or voxelSize0 (the stack's cascade-0 voxel) when that is 0; with neither known
  // (voxelSize0 <= 0) nothing is captured yet. record() uploads them with its next frame;
  // meshes added since the last capture have no cards until then (shaded as without cards).
  void prepareCards(const ObjectLibrary& library, double voxelSize0 = 0.0);
  // The same recorded into `batch` (uploads through `staging`'s current frame), no wait; its
  // passes are named "object_regions_*" in the batch's timings. lastTimings() is not updated.
  // lightsChanged: every instance's card light is stale (relit first, within the budget).
  // alongside: host work that needs only this frame's changed boxes (frame().changedBoxes) and
  // nothing else of the frame; it runs on a worker thread from the moment they are known, while
  // the rest of the frame is built and the card slots and commands are recorded, and record
  // returns after it has finished (rethrowing what it threw). GiSystem finds the light-cache
  // pages the moves shadow that way.
  void record(gpu::CommandBatch& batch, gpu::StagingRing& staging, const ObjectLibrary& library,
              const InstanceSet& instances, const CascadeStackImage& stack,
              bool lightsChanged = false, const std::function<void()>& alongside = {});

  // Something to bind this frame: instances, or regions where an instance was just removed (the
  // probes there must still wake up). False: passes bind NoObjectsBindings instead.
  bool active() const { return frame_.frame.counts.x > 0 || frame_.movedRegions > 0; }
  bool hasInstances() const { return frame_.frame.counts.x > 0; }
  // Bit c: some instance is listed in region cascade c (host AABB level, size rule applied).
  std::uint32_t cascadeMask() const { return frame_.cascadeMask; }
  const ObjectFrameData& frame() const { return frame_; }
  const ObjectSceneSettings& settings() const { return settings_; }
  void setNaiveTraversal(bool naive) { settings_.naiveTraversal = naive; }

  // The eight buffers of object_bindings.glsl, in binding order.
  std::array<const gpu::Buffer*, 8> buffers() const {
    return {&meta_,     &instances_, &regions_,  &lists_,
            &distance_, &material_,  &cardData_, &cardLight_};
  }
  // Card light of this frame (shaders/card_light.comp, dispatched by the light cache): the
  // instance indices to relight, uploaded by record(), and the buffer the pass writes.
  std::uint32_t cardRelightCount() const { return std::uint32_t(relight_.size()); }
  // Texels of the largest card of any mesh: the card light pass spreads each instance over
  // ceil(this / 64) workgroups.
  std::uint32_t maxCardTexels() const { return maxCardTexels_; }
  const gpu::Buffer& cardRelightList() const { return relightList_; }
  const gpu::Buffer& cardLight() const { return cardLight_; }
  const CardLightSlots::Stats& cardStats() const { return slots_.stats(); }
  // Texels of mesh m's cards (0: none), and the card atlas as uploaded (the table of every
  // mesh's six CardGpu, then the texels; CardGpu::first.y indexes the texels from the start).
  const std::vector<std::uint32_t>& cardMeshTexels() const { return meshTexels_; }
  const std::vector<gpu_shared::CardGpu>& cardTable() const { return cardTable_; }
  const std::vector<gpu_shared::CardTexelGpu>& cardTexels() const { return cardTexels_; }
  std::vector<std::uint32_t> downloadCardLight() const;
  // Card light texels whose radiance came out NaN or infinite since the scene was made (the pass
  // counts them before RGB9E5 packing turns NaN into 0 and infinity into its largest value), and
  // the buffer it counts into (binding 16 of card_light.comp). Blocking download.
  std::uint64_t cardNonFiniteTexels() const;
  const gpu::Buffer& cardNonFiniteCounter() const { return cardNonFinite_; }
  // Device bytes of the card atlas and the card light (what cards cost in memory).
  std::size_t cardBytes() const { return cardData_.size() + cardLight_.size(); }
  // GPU milliseconds of the last card capture (the meshes new since the one before), 0 if none.
  double lastCaptureMilliseconds() const { return captureMilliseconds_; }

  // Rays (stack space) against the objects only: through the region lists, or every instance
  // (bruteForce: the naive peer). Blocking; for tests and the stress benchmark.
  std::vector<gpu_shared::ObjectTraceHit> trace(std::span<const gpu_shared::TraceRay> rays,
                                                bool bruteForce);

  // Timed passes record() adds to a batch: count, rank, scan, sub-cell count and scan, fill.
  static constexpr std::uint32_t kRegionPasses = 6;

  std::vector<gpu_shared::ObjectRegionGpu> downloadRegions() const;
  // OBJ_LIST: the region lists' entries (objListEntry in shaders/object_trace.glsl: instance
  // index in x), then the sub-cell headers and the sub-cell entries (object_layout.h).
  std::vector<glm::uvec4> downloadLists() const;
  // GPU times of the last update's region passes (count, rank, scan, sub-cell count and scan,
  // fill); empty when inactive.
  const std::vector<gpu::PassTiming>& lastTimings() const { return timings_; }
  const std::vector<gpu::PassTiming>& lastTraceTimings() const { return traceTimings_; }
  // CPU time of the last record's buildObjectFrame (the rest of record is uploads).
  double lastBuildMilliseconds() const { return buildMilliseconds_; }
  // ... of which assigning the card light blocks (CardLightSlots::assign).
  double lastCardsMilliseconds() const { return cardsMilliseconds_; }
  std::size_t deviceBytes() const;

 private:
  void recordAtlas(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                   const ObjectLibrary& library);
  void uploadCards(gpu::CommandBatch& batch, gpu::StagingRing& staging);
  std::size_t listEntries() const;  // OBJ_LIST's uvec4s this frame
  // record() once frame_ is built: the card slots, the uploads and the region passes.
  void recordBuilt(gpu::CommandBatch& batch, gpu::StagingRing& staging, bool lightsChanged,
                   const CascadeStackImage& stack,
                   std::chrono::steady_clock::time_point buildStart);
  void recordCardLight(gpu::CommandBatch& batch, gpu::StagingRing& staging, bool lightsChanged,
                       glm::vec3 viewer, float levelBeyond);

  gpu::Context& context_;
  ObjectSceneSettings settings_;
  gpu::ComputePipeline regionsPipeline_, scanPipeline_, tracePipeline_;
  // Device-local; meta, instances and the regions' initial state are written every frame
  // through the staging ring.
  gpu::Buffer meta_, instances_, regions_, lists_, distance_, material_;
  // Cards: the atlas (uvec4s: table, then texels), each instance's light, this frame's list.
  gpu::Buffer cardData_, cardLight_, relightList_;
  gpu::Buffer cardNonFinite_;  // one uint: texels whose light came out NaN or Inf (card_light.comp)
  std::unique_ptr<CardRasterizer> rasterizer_;
  CardLightSlots slots_;
  std::vector<std::uint32_t> meshTexels_, relight_;
  std::vector<std::uint32_t> meshLevelTexels_;  // per mesh and card light level
  std::uint32_t maxCardTexels_ = 0;
  std::vector<gpu_shared::CardGpu> cardTable_;
  std::vector<gpu_shared::CardTexelGpu> cardTexels_;
  double captureMilliseconds_ = 0.0;
  std::uint64_t cardsVersion_ = ~std::uint64_t(0);
  std::uint32_t capturedMeshes_ = 0;  // the library's first meshes whose cards are captured
  double cardsTexelWorld_ = 0.0;      // the texel size they were captured at
  bool cardsUploaded_ = true;
  gpu::Buffer rays_, hits_;
  std::uint64_t atlasVersion_ = ~std::uint64_t(0);
  std::vector<gpu_shared::ObjectMeshGpu> meshes_;
  ObjectFrameData frame_;
  friend class GiSystem;  // sets the last timings/stats of recorded frames
  std::vector<gpu::PassTiming> timings_, traceTimings_;
  double buildMilliseconds_ = 0.0;
  double cardsMilliseconds_ = 0.0;
};

}  // namespace sdfstream
