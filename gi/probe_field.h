// The probe field on the GPU: one DDGI probe volume per SDF cascade, updated each
// frame by compute passes over storage buffers --
//   classify (scroll reset, SDF relocation, states, hit-cache invalidation; every probe)
//   -> select (count per priority class, append within the ray budget, size the next passes)
//   -> trace + shade (hit cache, else sphere tracing through the stack; light cache + previous
//      irradiance at hits, through the bounce cells; sky at misses) -> the bounce cells' lookups
//      -> blend interior texels, each with its border copies
// and irradiance(x, n, view) queries across cascades (probe_sample.comp). The math is
// shaders/probe_field.glsl; gi/probe_field_cpu.h is the CPU reference of the same passes.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "gi/gpu_stack_scene.h"
#include "gi/object_scene.h"
#include "gi/probe_field_cpu.h"
#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "gpu/compute_pipeline.h"
#include "gpu/context.h"
#include "gpu/staged_buffer.h"
#include "gpu/staging_ring.h"

namespace sdfstream {
class GiSystem;
}

namespace sdfstream::probe {

class ProbeField {
 public:
  // Allocates every buffer (probeFieldSizes(settings, cascades).bytes() of device memory).
  ProbeField(gpu::Context& context, const ProbeFieldSettings& settings, std::uint32_t cascades);

  // Makes the passes' pipelines for the atlas the scene will most likely hold
  // (GpuStackScene::cellCorners), and list sampling's, now rather than in the first frame that
  // records them. Optional: a frame makes whatever variant it needs and has not got yet.
  void preparePipelines(bool cellCorners);

  // One frame: `scene` holds the stack the image describes (already synced), `lightRadiance`
  // the light cache (gi/light_cache.h). Blocking; reads back the frame statistics.
  void update(const GpuStackScene& scene, const CascadeStackImage& image,
              const gpu::Buffer& lightRadiance, const ProbeFrameInputs& inputs,
              std::uint64_t frame);
  // The same recorded into `batch` (uploads through `staging`'s current frame), no wait. The
  // frame statistics are copied into the readback slot staging.currentSlot(); read them with
  // readStats(slot) once the batch has completed. lastStats()/lastTimings() are not updated.
  void record(gpu::CommandBatch& batch, gpu::StagingRing& staging, const GpuStackScene& scene,
              const CascadeStackImage& image, const gpu::Buffer& lightRadiance,
              const ProbeFrameInputs& inputs, std::uint64_t frame);
  // Statistics of the frame recorded in readback slot `slot`. Precondition: that frame's batch
  // has completed (CommandBatch::completed); never waits.
  ProbeFieldStats readStats(std::uint32_t slot) const;
  void reset();
  // The bounce cells for an atlas of `slots` brick slots, allocated now (blocking), so that a
  // host reserving the atlas (GiSystem::reserveAtlasSlots) learns whether both fit; otherwise
  // they grow with the atlas in record(). Throws gpu::OutOfDeviceMemory where the device cannot
  // hold them (the cells are then empty, to be reserved again for fewer slots).
  void reserveBounceCells(std::uint32_t slots);
  // Moving objects the next updates trace and classify against, or none (nullptr):
  // the object scene must be updated for the same stack before each update() and outlive it.
  void setObjects(const ObjectScene* objects) { objects_ = objects; }

  // irradiance(x, n, view) of the current probes at each query (0 where its normal is zero: a
  // pixel without a surface); blocking. Fastest with the
  // queries of a screen in 8×8 pixel tiles, Z-order inside (as bench gi gives them: 8
  // consecutive queries are a 4×2 block): neighbours then share probe cages and SDF tests
  // (ProbeFieldSettings::shareSdfTests) and a warp's loads coincide; Sponza at 1080p on an H100,
  // 1.88 ms against 2.68 in pixel rows (docs/GPU_BUDGET.md).
  std::vector<glm::vec3> sample(const GpuStackScene& scene, const gpu::Buffer& lightRadiance,
                                std::span<const gpu_shared::ProbeQuery> queries);
  // The same at reduced resolution, for an image of queries (width × height, row by row; a
  // pixel without a surface has a zero normal and gets 0): one query per blockSize × blockSize
  // block is sampled (2: half resolution, 4: quarter), the others are filled in by a
  // depth/normal-aware upsample (shaders/probe_upsample.glsl), so sampling costs about
  // 1 / blockSize², at an error bench gi measures (its `half-res` and `quarter-res` configs).
  // Blocking; lastTimings() then holds probe_sample and probe_upsample.
  std::vector<glm::vec3> sampleHalfResolution(const GpuStackScene& scene,
                                              const gpu::Buffer& lightRadiance,
                                              std::span<const gpu_shared::ProbeQuery> image,
                                              std::uint32_t width, std::uint32_t height,
                                              std::uint32_t blockSize = 2);

  // The probe buffers an engine's shader samples (sdfstream/probe_sample.glsl, bindings 0-4):
  // frame constants, volumes, probe data, irradiance, depth.
  std::array<const gpu::Buffer*, 5> sampleBuffers() const {
    return {&frame_, &volumes_, &data_, &irradiance_, &depth_};
  }
  const ProbeFieldSettings& settings() const { return settings_; }
  const ProbeFieldStats& lastStats() const { return stats_; }
  // GPU time per pass of the last update() or sample(): probe_classify, probe_cache_check (frames
  // whose windows scrolled or pages changed), probe_select_count,
  // probe_select_emit, probe_select_args, probe_trace, probe_bounce_cells, probe_bounce_rays and
  // probe_bounce_own (with bounce cells), probe_blend / probe_sample.
  const std::vector<gpu::PassTiming>& lastTimings() const { return timings_; }
  double lastMilliseconds() const;
  // Every buffer's bytes, the bounce cells as large as the atlas they last grew to.
  std::size_t deviceBytes() const { return sizes_.bytes() + bounceCellVoxels_ * 8; }

  std::vector<glm::vec4> downloadIrradiance() const;
  std::vector<glm::vec2> downloadDepth() const;
  std::vector<glm::vec4> downloadProbeData() const;
  std::vector<glm::uvec2> downloadHitCache() const;
  // The last update's probe rays (diagnosis): the first `listed` entries of the update list
  // (global probe indices; listed = ProbeFieldStats::probesUpdated, clamped to the capacity) and,
  // at list position x rays per probe + ray, what each ray brought back (radiance, depth; depth
  // negated on a backface) and its direction.
  struct RayRecords {
    std::vector<std::uint32_t> list;
    std::vector<glm::vec4> results, directions;
  };
  RayRecords downloadRays(std::uint32_t listed) const;

 private:
  // distanceAtlas: bind the stack's distance atlas, not the one it traces (probe_sample.comp).
  // results: what binding 19 (the sampling pass's results) binds instead of results_.
  std::vector<const gpu::Buffer*> bindings(const GpuStackScene& scene,
                                           const gpu::Buffer& lightRadiance,
                                           bool distanceAtlas = false,
                                           const gpu::Buffer* results = nullptr);
  // Reads `count` results back through results_ once `batch` has sampled them, and keeps its
  // timings.
  std::vector<glm::vec3> finishSampling(gpu::CommandBatch& batch, std::size_t count);
  // Sizes the bounce cells to the scene's atlas (new cells empty; recorded into `batch`).
  void growBounceCells(gpu::CommandBatch& batch, const GpuStackScene& scene);

  gpu::Context& context_;
  ProbeFieldSettings settings_;
  std::uint32_t cascades_;
  ProbeFieldSizes sizes_;
  ProbeFieldFrameBuilder builder_;
  ProbeFieldFrame lastFrame_;
  // The ray pattern the device buffer holds (kept, so a new pattern never shares its address).
  std::shared_ptr<const std::vector<glm::vec4>> uploadedPattern_;
  // The passes that bind the traced atlas, specialized on which one it is
  // (GpuStackScene::cellCorners, sdf_trace.glsl kSdfCellCorners); sampling binds the distances.
  gpu::ComputePipelinePair classify_, cacheCheck_, select_, trace_, bounce_, blend_;
  // sample_: probe_sample.comp's variants (constant 0: bit 0 half resolution, bit 1 the
  // near-field gather), each compiled on first use; sampleVariant picks the settings' one.
  gpu::ComputePipelinePair sample_;
  const gpu::ComputePipeline& sampleVariant(bool halfResolution);
  gpu::ComputePipeline upsample_;
  // frame_, volumes_ and pageChanged_ are written every frame through the staging ring,
  // rayPattern_ whenever the frame's pattern is a new one; the statistics go back through one
  // readback buffer per frame in flight.
  gpu::Buffer frame_, volumes_, data_, history_, irradiance_, depth_, rays_, cache_, rayPattern_,
      list_, statsBuffer_, pageChanged_;
  std::vector<gpu::Buffer> statsReadback_;
  gpu::StagedBuffer queries_, results_;  // sample()'s, device-local (gpu/staged_buffer.h)
  gpu::Buffer halfResults_;              // sampleHalfResolution()'s low-resolution samples
  // Group counts of the trace / bounce passes (x, y, z at 0) and the blend (at 3), written by
  // probe_select's args mode.
  gpu::Buffer dispatchArgs_;
  gpu::Buffer rayDirs_;       // this frame's ray directions, for the blend
  gpu::Buffer bounceCells_;   // uvec2 per atlas material voxel (probe_trace.glsl, bounce cells)
  gpu::Buffer bounceWork_;    // the bounce passes' lists (ProbeFieldSizes::bounceWork)
  std::size_t bounceCellVoxels_ = 0;
  const ObjectScene* objects_ = nullptr;
  NoObjectsBindings noObjects_;  // bound at 22-29 when there are no objects
  ProbeFieldStats stats_;
  friend class ::sdfstream::GiSystem;  // sets the last timings/stats of recorded frames
  std::vector<gpu::PassTiming> timings_;
};

}  // namespace sdfstream::probe
