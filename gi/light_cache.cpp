// The GPU half of gi/light_cache.h: light_cache.comp over the dirty pages' cells.
#include "gi/light_cache.h"

#include <algorithm>
#include <cassert>
#include <cstring>

namespace sdfstream {
namespace {
constexpr glm::uvec3 kGroup(64, 1, 1);
constexpr std::uint32_t kBindings = 16;      // 8 + 8 object bindings (light_cache.comp)
constexpr std::uint32_t kCardBindings = 17;  // the same + the non-finite counter (card_light.comp)
}  // namespace

LightCache::LightCache(gpu::Context& context, LightCacheSettings settings)
    : context_(context),
      settings_(settings),
      pipeline_(context, gpu::ShaderId::light_cache,
                gpu::PipelineDesc{kBindings, sizeof(gpu_shared::LightCachePushConstants), kGroup}),
      cardPipeline_(
          context, gpu::ShaderId::card_light,
          gpu::PipelineDesc{kCardBindings, sizeof(gpu_shared::LightCachePushConstants), kGroup}),
      radiance_(context, 4, gpu::BufferKind::DeviceLocal),
      pageList_(context, 4096 * sizeof(std::uint32_t), gpu::BufferKind::DeviceLocal),
      lights_(context, gpu_shared::kMaxLights * sizeof(gpu_shared::GpuLight),
              gpu::BufferKind::DeviceLocal),
      noObjects_(context) {
  const std::uint32_t zero = 0;
  radiance_.upload(&zero, sizeof zero);
}

void LightCache::grow(gpu::CommandBatch& batch, std::size_t materialVoxels) {
  if (materialVoxels <= materialVoxels_) return;
  gpu::Buffer bigger(context_, materialVoxels * sizeof(std::uint32_t),
                     gpu::BufferKind::DeviceLocal);
  batch.fill(bigger, 0u);
  // Slots already lit keep their light: the atlas grew, the scene did not change.
  if (materialVoxels_ > 0) batch.copy(radiance_, bigger, materialVoxels_ * sizeof(std::uint32_t));
  radiance_ = std::move(bigger);  // the old one outlives the batch (deferred destruction)
  materialVoxels_ = materialVoxels;
}

void LightCache::update(const GpuStackScene& scene, std::span<const gpu_shared::GpuLight> lights,
                        const gpu_shared::GpuSky& sky, std::span<const std::uint32_t> dirtyPages,
                        double voxelSize0, const ObjectScene* objects) {
  gpu::StagingRing staging(context_, 1);
  gpu::CommandBatch batch = context_.beginBatch(2);
  staging.beginFrame();
  record(batch, staging, scene, lights, sky, dirtyPages, voxelSize0, objects);
  staging.endFrame(batch.submit());
  batch.wait();
  timings_ = batch.timings();
}

void LightCache::record(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                        const GpuStackScene& scene, std::span<const gpu_shared::GpuLight> lights,
                        const gpu_shared::GpuSky& sky, std::span<const std::uint32_t> dirtyPages,
                        double voxelSize0, const ObjectScene* objects) {
  assert(lights.size() <= gpu_shared::kMaxLights);
  assert(dirtyPages.size() <= 65535 &&
         "one page per workgroup row; lightDirtyPages gives <= 32768");
  grow(batch, std::size_t(scene.slotCount()) * gpu_shared::kBrickMaterialCount);
  pagesRelit_ = 0;
  timings_.clear();
  const std::uint32_t cards = objects && objects->hasInstances() ? objects->cardRelightCount() : 0u;
  // Skip what is not needed.
  if ((dirtyPages.empty() && cards == 0) || scene.cascadeCount() == 0) return;
  staging.upload(batch, lights_, lights);
  const auto objectBuffers =
      objects && objects->active() ? objects->buffers() : noObjects_.buffers();

  if (!dirtyPages.empty()) {
    pagesRelit_ = std::uint32_t(dirtyPages.size());
    if (pageList_.size() < dirtyPages.size_bytes())
      pageList_ = gpu::Buffer(context_, dirtyPages.size_bytes(), gpu::BufferKind::DeviceLocal);
    staging.upload(batch, pageList_, dirtyPages);
    gpu_shared::LightCachePushConstants pc = lightCachePushConstants(
        settings_, std::uint32_t(dirtyPages.size()), std::uint32_t(lights.size()),
        scene.cascadeCount(), sky, voxelSize0);
    // Records what is bound, as the layout documents; no shader reads it (the variant decides).
    pc.params.z = scene.cellCorners() ? 1.0f : 0.0f;
    // One workgroup of 64 per listed page (y; at most 8 × 4096 < 65535), which walks its 512
    // cells.
    std::vector<const gpu::Buffer*> bufs = {
        &pageList_,          &lights_,        &radiance_,        &scene.pageTables(),
        &scene.traceAtlas(), &scene.albedo(), &scene.emission(), &scene.params()};
    bufs.insert(bufs.end(), objectBuffers.begin(), objectBuffers.end());
    batch.dispatch("light_cache", pipeline_.get(scene.cellCorners()), bufs, &pc, sizeof pc,
                   glm::uvec3(64, std::uint32_t(dirtyPages.size()), 1));
  }
  if (cards > 0) {
    // The listed instances' card light (card_light.comp): a row of workgroups per instance,
    // enough for its largest card (one workgroup per instance ran five large objects' cards on
    // five SMs: 1.15 ms a frame on the H200); the light buffer is both the pass's output and the
    // object binding the probes read later.
    gpu_shared::LightCachePushConstants pc = lightCachePushConstants(
        settings_, cards, std::uint32_t(lights.size()), scene.cascadeCount(), sky, voxelSize0);
    pc.params.z = scene.cellCorners() ? 1.0f : 0.0f;
    std::vector<const gpu::Buffer*> bufs = {
        &objects->cardRelightList(), &lights_,        &objects->cardLight(), &scene.pageTables(),
        &scene.traceAtlas(),         &scene.albedo(), &scene.emission(),     &scene.params()};
    bufs.insert(bufs.end(), objectBuffers.begin(), objectBuffers.end());
    bufs.push_back(&objects->cardNonFiniteCounter());
    const std::uint32_t groupsPerInstance = std::max(1u, (objects->maxCardTexels() + 63u) / 64u);
    batch.dispatch("light_cache_cards", cardPipeline_.get(scene.cellCorners()), bufs, &pc,
                   sizeof pc, glm::uvec3(64 * groupsPerInstance, cards, 1));
  }
}

std::vector<std::uint32_t> LightCache::downloadRadiance() const {
  std::vector<std::uint32_t> out(materialVoxels_);
  if (!out.empty()) radiance_.download(out.data(), out.size() * sizeof(std::uint32_t));
  return out;
}

}  // namespace sdfstream
