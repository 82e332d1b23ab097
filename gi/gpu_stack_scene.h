// The streamed cascade stack on the GPU: page tables, cascade params and the shared brick atlas
// (distance, albedo, emission) in device buffers. One instance is shared by every pass that
// reads the SDF (stack tracing, the light cache, the probe update), so the atlas is uploaded
// once per frame, and only the slots the stack rewrote.
//
// Corner atlas. Beside the distance atlas it keeps, where it can, the same distances regrouped by
// trilinear cell (sdf_layout.h kBrickCornerWords: 8 KiB a slot beside the distances' 1.46 KiB),
// built on the GPU from each uploaded slot, so a trace reads a sample in one load instead of 8.
// It is kept when asked for and when the device can bind it whole (slots x 8 KiB within
// maxStorageBufferRange, which is 128 MiB on some devices: 16,384 slots) and allocate it;
// otherwise the passes read the distance atlas. traceAtlas() is the one to bind, cellCorners()
// says which it is, and a tracing pass uses its pipeline specialized for that atlas
// (gpu::ComputePipelinePair; traces are the same either way, bit for bit); sampling and the
// engine's include always bind distance().
#pragma once

#include <cstdint>
#include <span>

#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "gpu/compute_pipeline.h"
#include "gpu/context.h"
#include "gpu/staging_ring.h"
#include "streaming/cascade_stack.h"

namespace sdfstream {

class GpuStackScene {
 public:
  explicit GpuStackScene(gpu::Context& context, bool cellCorners = true)
      : context_(context), cornersWanted_(cellCorners) {}

  // Timed passes an upload records into the caller's batch (the corners' regrouping).
  static constexpr std::uint32_t kUploadPasses = 1;

  // Whole-image upload (tests, analytic scenes, first frame), recorded into `batch` through the
  // staging ring (in its current frame). Buffers grow as needed (contents then start undefined
  // and are all rewritten here). Returns the bytes uploaded.
  std::size_t recordUploadAll(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                              const CascadeStackImage& image);
  // Per-frame sync from a streaming stack: page tables, params and the given dirty atlas slots
  // (CascadeStack::takeDirtySlots), recorded the same way (one copy command per array).
  // Allocates the atlas on first use. Returns the bytes uploaded.
  std::size_t recordSync(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                         const CascadeStack& stack, std::span<const std::uint32_t> dirtySlots);
  // The same, blocking (own batch and a one-slot ring): tests and tools.
  void uploadAll(const CascadeStackImage& image);
  std::size_t sync(const CascadeStack& stack, std::span<const std::uint32_t> dirtySlots);

  std::uint32_t cascadeCount() const { return cascadeCount_; }
  std::uint32_t slotCount() const { return slotCount_; }
  // Allocates the atlas buffers for `slots` brick slots before the first upload, halving the
  // count while the device has no memory for them (gpu::OutOfDeviceMemory), down to 64 slots
  // (then it rethrows). Returns the slots it could allocate; uploads never grow the atlas past
  // them, so the caller must keep the stack within them (CascadeStack::limitAtlasSlots).
  std::uint32_t reserveAtlas(std::uint32_t slots);
  // Mid-run, when the device ran out of memory: gives the atlas buffers back and reserves them
  // again for at most `slots` slots (reserveAtlas's halving and floor). The device atlas then
  // holds nothing: the caller must keep the stack within the returned slots and upload every
  // resident slot again.
  std::uint32_t shrinkAtlas(std::uint32_t slots);
  const gpu::Buffer& pageTables() const { return pageTables_; }
  const gpu::Buffer& distance() const { return distance_; }
  const gpu::Buffer& albedo() const { return albedo_; }
  const gpu::Buffer& emission() const { return emission_; }
  const gpu::Buffer& params() const { return params_; }
  // The atlas the tracing passes bind: the corner atlas when cellCorners(), else the distances.
  const gpu::Buffer& traceAtlas() const { return cornersOn_ ? corners_ : distance_; }
  bool cellCorners() const { return cornersOn_; }
  // The corner atlas (empty when cellCorners() is false).
  const gpu::Buffer& corners() const { return corners_; }

 private:
  // Sizes corners_ for `slots` (or drops it: not wanted, not bindable whole, out of memory).
  void ensureCorners(std::uint32_t slots);
  // Regroups the listed slots (every slot when `all`) of the distance atlas into corners_.
  void recordCorners(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                     std::span<const std::uint32_t> slots, bool all);
  void releaseAtlas();

  gpu::Context& context_;
  std::uint32_t cascadeCount_ = 0;
  std::uint32_t slotCount_ = 0;
  std::uint32_t slotCap_ = 0;  // reserveAtlas's slots; 0: as many as the stack has
  bool cornersWanted_ = true;
  bool cornersOn_ = false;
  gpu::Buffer pageTables_, distance_, albedo_, emission_, params_, corners_, cornerSlots_;
  gpu::ComputePipeline cornersPipeline_;  // created on the first upload
};

}  // namespace sdfstream
