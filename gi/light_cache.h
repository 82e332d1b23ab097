// The static voxel light cache (Godot SDFGI slides, "Filling the light texture
// with light" and "Caching light hits"): the outgoing direct radiance of every surface material
// voxel of the cascade stack -- emission + albedo/π · (sun, point and spot lights with SDF-traced
// soft shadows) -- stored per atlas material voxel as RGB9E5, indexed like the albedo/emission
// atlas (slot * 512 + cell). Probe rays read it where they hit instead of shading every hit.
// It is recomputed only for dirty pages: all resident pages when the lights change, otherwise the
// pages whose brick changed (lightDirtyPages). The math is shaders/light_math.glsl, run by
// light_cache.comp (LightCache) and, as C++, by the CPU reference LightCacheCpu.
//
// Not (yet): shadows cast by a newly streamed brick onto pages that did not change are picked up
// only when those pages are next relit; no indirect light (the probes add it); sky light is left
// to the probes (rays that miss see the sky).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "gi/gpu_stack_scene.h"
#include "gi/light_cache_work.h"
#include "gi/light_relight_queue.h"
#include "gi/object_scene.h"
#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "gpu/compute_pipeline.h"
#include "gpu/context.h"
#include "shaders/shared/light_layout.h"
#include "streaming/cascade_stack.h"

namespace sdfstream {

class GiSystem;

struct LightCacheSettings {
  // Sphere-tracing steps per shadow ray, over all cascades. Resident bricks cap a step at the
  // narrow band (3 voxels), so a ray crossing several cascades' occupied pages needs well over
  // 128: at 128, 52% of the cascade-2 cells Sponza's probe rays land on in sunlight were black
  // (out of steps counts as blocked); 256 lit all but 6% of them (bench gi --diagnose).
  std::uint32_t maxShadowSteps = 256;
  float hitEpsilon = 0.02f;  // voxels: a sample below this blocks the light
  // Pages relit per frame at most (LightRelightQueue: never-lit bricks first, then the longest
  // out of date); kRelightEveryPage relights every out-of-date page each frame.
  std::uint32_t relightPageBudget = kRelightEveryPage;
};

// Global page indices (cascade * 4096 + toroidal entry) whose cells need relighting, sorted:
//  - every resident page of `current` when lightsChanged, when there is no `previous`, or when
//    the cascade count or the voxel size changed;
//  - otherwise each page resident in `current` whose entry differs from `previous`, or whose
//    entry now holds another brick because its cascade scrolled (a released slot can be reused by
//    the entering page with the very same entry value).
// lightsChanged is about the lights in the world (e.g. SceneLights::version), not about their
// GpuLight form, which moves with cascade 0 although the light does not.
std::vector<std::uint32_t> lightDirtyPages(const CascadeStackImage* previous,
                                           const CascadeStackImage& current, bool lightsChanged);

// Resident pages of `stack` whose light a moving object may have changed (the light cache is
// re-lit only where objects moved): for the changed world boxes (InstanceSet::changedBounds or
// changedBoxes: old and new poses), every resident page a box overlaps or its shadow from a
// shadow-casting light may reach -- under a sun through a page-resolution shadow map per
// cascade, from a point/spot light by sweeping the box away from it until it leaves the stack.
// Conservative (never misses a page the shadow passes through). Sorted, distinct; merge with
// lightDirtyPages.
std::vector<std::uint32_t> objectShadowPages(const CascadeStackImage& stack,
                                             std::span<const WorldBox> changed,
                                             std::span<const gpu_shared::GpuLight> lights);

// Builds the push constants both implementations use. Asserts lights.size() <= kMaxLights.
gpu_shared::LightCachePushConstants lightCachePushConstants(
    const LightCacheSettings& settings, std::uint32_t pageCount, std::uint32_t lightCount,
    std::uint32_t cascadeCount, const gpu_shared::GpuSky& sky, double voxelSize0);

// skyRadiance of shaders/light_math.glsl for C++ callers: the radiance of `sky` along unit `dir`.
glm::vec3 skyRadianceCpu(const gpu_shared::GpuSky& sky, glm::vec3 dir);

// Why the light-cache cell holding a point holds what it holds (diagnosis; the steps of
// lightCacheCellRadiance for one light, on the CPU): the cell of cascade `cascade` containing
// p0 (cascade-0 voxels), its SDF sample at the centre, normal, surface point, n·L, the cascade
// its shadow ray starts in and the shadow's visibility. `light` in cascade-0 voxels (toGpu).
struct LightCellSteps {
  bool resident = false;            // the point's page holds a brick
  bool inBand = false;              // |d(centre)| <= kLightSurfaceBand: a surface cell, lit
  float distance = 0.0f;            // d(centre), the cascade's voxels
  glm::vec3 normal{0.0f};           // SDF gradient at the centre
  glm::vec3 surface0{0.0f};         // centre - n d, cascade-0 voxels
  float cosine = 0.0f;              // n · (the way to the light)
  std::uint32_t shadowCascade = 0;  // finest cascade holding the surface point
  float visibility = 0.0f;          // of the shadow ray (0 when not traced)
};
LightCellSteps lightCellSteps(const CascadeStackImage& stack, const gpu_shared::GpuLight& light,
                              std::uint32_t cascade, glm::vec3 p0,
                              const LightCacheSettings& settings = {});

// The light cache's material voxel (slot * kBrickMaterialCount + cell) holding the point p0
// (cascade-0 voxels) in cascade `cascade`, or -1 where its page holds no brick: the index of
// LightCache::downloadRadiance() a hit there reads.
std::int64_t lightMaterialAt(const CascadeStackImage& stack, std::uint32_t cascade, glm::vec3 p0);

// What relighting every resident page of `stack` under `lights` (cascade-0 voxels, toGpu; at
// most kMaxLights) asks of the light cache pass, counted on the CPU with the same math
// (gi/light_cache_work.h).
LightCacheWork lightCacheWork(const CascadeStackImage& stack,
                              std::span<const gpu_shared::GpuLight> lights,
                              const LightCacheSettings& settings = {});

// CPU reference of the same math (TBB over pages × cells). Not thread safe; update() blocks.
class LightCacheCpu {
 public:
  explicit LightCacheCpu(LightCacheSettings settings = {}) : settings_(settings) {}

  // Relights the cells of each listed page that is resident in `stack` (others are skipped;
  // pages must be distinct, as lightDirtyPages returns them: cells are written in parallel);
  // every other slot keeps its value. Lights in cascade-0 voxels (toGpu), at most kMaxLights;
  // voxelSize0 in metres. The storage grows (new slots 0) to the stack's atlas size.
  void update(const CascadeStackImage& stack, std::span<const gpu_shared::GpuLight> lights,
              const gpu_shared::GpuSky& sky, std::span<const std::uint32_t> dirtyPages,
              double voxelSize0);

  // One RGB9E5 per atlas material voxel (slot * 512 + cell), sized like the albedo atlas.
  std::span<const std::uint32_t> radiance() const { return radiance_; }
  std::uint32_t pagesRelitLastUpdate() const { return pagesRelit_; }

 private:
  LightCacheSettings settings_;
  std::vector<std::uint32_t> radiance_;
  std::uint32_t pagesRelit_ = 0;
};

// The GPU light cache (light_cache.comp). Owns the light atlas and small device-local buffers
// (written through the staging ring) for the page list and the lights. Thread safety: as for the
// Context.
class LightCache {
 public:
  // Throws std::runtime_error when a Vulkan allocation fails.
  explicit LightCache(gpu::Context& context, LightCacheSettings settings = {});

  // Relights the listed pages against `scene` (which must hold the stack these page indices and
  // lights refer to); blocking. Grows the light atlas to scene.slotCount() first (old values
  // kept, new slots zero). Same units and limits as LightCacheCpu::update; at most 65535 pages
  // (asserted; a stack has <= 32768). `objects` (optional, updated for the same stack): moving
  // objects block the shadow rays (hard shadows; the GPU pass only -- the CPU reference has no
  // objects), and the instances on objects->cardRelightList() get their card light recomputed
  // (card_light.comp, pass "light_cache_cards"). Dispatches nothing when there are neither
  // dirty pages nor instances to relight.
  void update(const GpuStackScene& scene, std::span<const gpu_shared::GpuLight> lights,
              const gpu_shared::GpuSky& sky, std::span<const std::uint32_t> dirtyPages,
              double voxelSize0, const ObjectScene* objects = nullptr);
  // Makes the passes' pipelines for the atlas the scene will most likely hold
  // (GpuStackScene::cellCorners) now rather than in the first frame that records them. Optional:
  // a frame makes whatever variant it needs and has not got yet.
  void preparePipelines(bool cellCorners) {
    pipeline_.get(cellCorners);
    cardPipeline_.get(cellCorners);
  }
  // The same recorded into `batch` (uploads through `staging`'s current frame), no wait; its
  // passes are named "light_cache" and "light_cache_cards" in the batch's timings.
  // lastTimings() is not updated.
  void record(gpu::CommandBatch& batch, gpu::StagingRing& staging, const GpuStackScene& scene,
              std::span<const gpu_shared::GpuLight> lights, const gpu_shared::GpuSky& sky,
              std::span<const std::uint32_t> dirtyPages, double voxelSize0,
              const ObjectScene* objects = nullptr);

  // Device-local light atlas: one RGB9E5 uint per material voxel, zero-filled on creation/growth.
  const gpu::Buffer& radianceBuffer() const { return radiance_; }
  std::vector<std::uint32_t> downloadRadiance() const;  // blocking
  std::size_t materialVoxelCount() const { return materialVoxels_; }

  // GPU time of the last update's pass ("light_cache"); empty when it dispatched nothing.
  const std::vector<gpu::PassTiming>& lastTimings() const { return timings_; }
  // Pages listed in the last update (each relit if resident); 0 when it was skipped.
  std::uint32_t pagesRelitLastUpdate() const { return pagesRelit_; }
  const LightCacheSettings& settings() const { return settings_; }

 private:
  void grow(gpu::CommandBatch& batch, std::size_t materialVoxels);

  gpu::Context& context_;
  LightCacheSettings settings_;
  // Specialized on the atlas the scene traces (GpuStackScene::cellCorners).
  gpu::ComputePipelinePair pipeline_, cardPipeline_;
  gpu::Buffer radiance_;  // device-local light atlas
  gpu::Buffer pageList_;  // device-local, grown on demand; written through the staging ring
  gpu::Buffer lights_;    // device-local, kMaxLights GpuLight; written through the staging ring
  NoObjectsBindings noObjects_;
  std::size_t materialVoxels_ = 0;
  friend class GiSystem;  // sets the last timings/stats of recorded frames
  std::vector<gpu::PassTiming> timings_;
  std::uint32_t pagesRelit_ = 0;
};

}  // namespace sdfstream
