#include "gi/probe_field.h"

#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "gi/probe_upsample.h"

namespace sdfstream::probe {
namespace {
using gpu_shared::ProbePushConstants;
constexpr std::uint32_t kBindings = 32;  // 22 probe + 8 object + 2 bounce (probe_bindings.glsl)
constexpr glm::uvec3 kGroup(64, 1, 1);

gpu::PipelineDesc pipelineDesc() {
  return gpu::PipelineDesc{kBindings, sizeof(ProbePushConstants), kGroup};
}

gpu::ComputePipelinePair tracingPipeline(gpu::Context& ctx, gpu::ShaderId id) {
  return gpu::ComputePipelinePair(ctx, id, pipelineDesc());
}

gpu::Buffer deviceBuffer(gpu::Context& ctx, std::size_t bytes) {
  return gpu::Buffer(ctx, bytes, gpu::BufferKind::DeviceLocal);
}

// Threads spread over rows (probeInvocation() in probe_bindings.glsl).
glm::uvec3 spread(std::uint32_t threads) { return gpu::spreadOverRows(threads); }

}  // namespace

ProbeField::ProbeField(gpu::Context& context, const ProbeFieldSettings& settings,
                       std::uint32_t cascades)
    : context_(context),
      settings_(settings),
      cascades_(cascades),
      sizes_(probeFieldSizes(settings, cascades)),
      builder_(settings),
      classify_(tracingPipeline(context, gpu::ShaderId::probe_classify)),
      cacheCheck_(tracingPipeline(context, gpu::ShaderId::probe_cache_check)),
      select_(tracingPipeline(context, gpu::ShaderId::probe_select)),
      trace_(tracingPipeline(context, gpu::ShaderId::probe_trace)),
      bounce_(tracingPipeline(context, gpu::ShaderId::probe_bounce)),
      blend_(tracingPipeline(context, gpu::ShaderId::probe_blend)),
      sample_(context, gpu::ShaderId::probe_sample, pipelineDesc()),
      upsample_(context, gpu::ShaderId::probe_upsample,
                gpu::PipelineDesc{3, sizeof(ProbePushConstants), kGroup}),
      frame_(deviceBuffer(context, sizeof(gpu_shared::ProbeFrame))),
      volumes_(deviceBuffer(context, cascades * sizeof(gpu_shared::ProbeVolume))),
      data_(deviceBuffer(context, sizes_.probes * 16)),
      history_(deviceBuffer(context, sizes_.probes * 16)),
      irradiance_(deviceBuffer(context, sizes_.irradianceTexels * 16)),
      depth_(deviceBuffer(context, sizes_.depthTexels * 8)),
      rays_(deviceBuffer(context, sizes_.rays * 16)),
      cache_(deviceBuffer(context, sizes_.cacheEntries * 8)),
      rayPattern_(deviceBuffer(
          context, std::size_t(std::max(1u, settings.cacheRotations)) *
                       (3 + gpu_shared::kProbeDepthInterior * gpu_shared::kProbeDepthInterior *
                                gpu_shared::kProbeDepthListVec4s) *
                       16)),
      list_(deviceBuffer(context, std::size_t(settings.listCapacity(cascades)) * 4)),
      statsBuffer_(deviceBuffer(context, gpu_shared::kProbeStatCount * 4)),
      pageChanged_(deviceBuffer(context, std::size_t(cascades) * 128 * 4)),
      queries_(context, gpu::StagedBuffer::ToDevice),
      results_(context, gpu::StagedBuffer::ToHost),
      dispatchArgs_(deviceBuffer(context, 6 * 4)),
      rayDirs_(deviceBuffer(context, sizes_.rays * 16)),
      bounceCells_(deviceBuffer(context, 8)),
      bounceWork_(deviceBuffer(context, sizes_.bounceWork * 16)),
      noObjects_(context) {
  // Bound by every pass, so they exist before the first sample().
  queries_.reserve(sizeof(gpu_shared::ProbeQuery));
  results_.reserve(sizeof(glm::vec4));
  reset();
}

void ProbeField::reset() {
  gpu::CommandBatch batch = context_.beginBatch();
  for (gpu::Buffer* b :
       {&data_, &history_, &irradiance_, &depth_, &cache_, &list_, &statsBuffer_, &bounceCells_})
    batch.fill(*b, 0u);
  batch.submitAndWait();
  builder_.reset();
  uploadedPattern_.reset();  // uploaded again with the next frame
}

std::vector<const gpu::Buffer*> ProbeField::bindings(const GpuStackScene& scene,
                                                     const gpu::Buffer& light, bool distanceAtlas,
                                                     const gpu::Buffer* results) {
  std::vector<const gpu::Buffer*> b = {&frame_,
                                       &volumes_,
                                       &data_,
                                       &history_,
                                       &irradiance_,
                                       &depth_,
                                       &rays_,
                                       &cache_,
                                       &rayPattern_,
                                       &list_,
                                       &statsBuffer_,
                                       &pageChanged_,
                                       &scene.pageTables(),
                                       distanceAtlas ? &scene.distance() : &scene.traceAtlas(),
                                       &scene.albedo(),
                                       &scene.emission(),
                                       &scene.params(),
                                       &light,
                                       &queries_.device(),
                                       results ? results : &results_.device(),
                                       &dispatchArgs_,
                                       &rayDirs_};
  for (const gpu::Buffer* o :
       objects_ && objects_->active() ? objects_->buffers() : noObjects_.buffers())
    b.push_back(o);
  b.push_back(&bounceCells_);
  b.push_back(&bounceWork_);
  return b;
}

void ProbeField::reserveBounceCells(std::uint32_t slots) {
  const std::size_t voxels = std::size_t(slots) * gpu_shared::kBrickMaterialCount;
  if (settings_.bounceCellUpdates == 0 || voxels == bounceCellVoxels_) return;
  bounceCells_ = deviceBuffer(context_, 8);  // the old cells' memory back first
  bounceCellVoxels_ = 0;
  gpu::Buffer cells = deviceBuffer(context_, std::max<std::size_t>(voxels, 1) * 8);
  gpu::CommandBatch batch = context_.beginBatch();
  batch.fill(cells, 0u);
  batch.submitAndWait();
  bounceCells_ = std::move(cells);
  bounceCellVoxels_ = voxels;
}

void ProbeField::growBounceCells(gpu::CommandBatch& batch, const GpuStackScene& scene) {
  const std::size_t voxels = std::size_t(scene.slotCount()) * gpu_shared::kBrickMaterialCount;
  if (settings_.bounceCellUpdates == 0 || voxels <= bounceCellVoxels_) return;
  // A cache: the grown cells start empty and are looked up again where rays hit them.
  bounceCells_ = deviceBuffer(context_, voxels * 8);  // the old one outlives the batch
  batch.fill(bounceCells_, 0u);
  bounceCellVoxels_ = voxels;
}

void ProbeField::update(const GpuStackScene& scene, const CascadeStackImage& image,
                        const gpu::Buffer& light, const ProbeFrameInputs& inputs,
                        std::uint64_t frame) {
  gpu::StagingRing staging(context_, 1);
  gpu::CommandBatch batch = context_.beginBatch();
  staging.beginFrame();
  record(batch, staging, scene, image, light, inputs, frame);
  staging.endFrame(batch.submit());
  batch.wait();
  timings_ = batch.timings();
  stats_ = readStats(0);
}

void ProbeField::preparePipelines(bool cellCorners) {
  for (gpu::ComputePipelinePair* p :
       {&classify_, &cacheCheck_, &select_, &trace_, &bounce_, &blend_})
    p->get(cellCorners);
  sampleVariant(false);  // a list of queries; half resolution compiles on first use
}

void ProbeField::record(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                        const GpuStackScene& scene, const CascadeStackImage& image,
                        const gpu::Buffer& light, const ProbeFrameInputs& inputs,
                        std::uint64_t frame) {
  lastFrame_ = builder_.build(image, inputs, frame);
  growBounceCells(batch, scene);
  // Records what is bound, as the layout documents; no shader reads it (the variants decide).
  if (scene.cellCorners()) lastFrame_.constants.options.x |= gpu_shared::kProbeOptionCellCorners;
  if (objects_ && objects_->active()) {
    lastFrame_.constants.options.x |=
        gpu_shared::kProbeOptionObjects |
        (objects_->cascadeMask() << gpu_shared::kProbeObjectMaskShift);
    if (objects_->settings().naiveTraversal)
      lastFrame_.constants.options.x |= gpu_shared::kProbeOptionObjectsNaive;
  }
  staging.upload(batch, frame_, 0, &lastFrame_.constants, sizeof lastFrame_.constants);
  staging.upload(batch, volumes_, std::span(std::as_const(lastFrame_.volumes)));
  // With the hit cache every frame shares one pattern: uploaded once.
  if (lastFrame_.rayPattern != uploadedPattern_) {
    staging.upload(batch, rayPattern_, std::span(*lastFrame_.rayPattern));
    uploadedPattern_ = lastFrame_.rayPattern;
  }
  staging.upload(batch, pageChanged_, std::span(std::as_const(lastFrame_.pageChanged)));
  while (statsReadback_.size() < staging.framesInFlight())
    statsReadback_.emplace_back(context_, gpu_shared::kProbeStatCount * 4,
                                gpu::BufferKind::Readback);

  const std::vector<const gpu::Buffer*> b = bindings(scene, light);
  const bool corners = scene.cellCorners();
  const std::uint32_t probes = std::uint32_t(sizes_.probes);
  const std::uint32_t capacity = settings_.listCapacity(cascades_);
  auto push = [](std::uint32_t mode, std::uint32_t threads) {
    ProbePushConstants pc{};
    pc.dispatch = glm::uvec4(mode, threads, 0u, 0u);
    return pc;
  };
  const ProbePushConstants classify = push(0, probes);
  const std::uint32_t cacheEntries = std::uint32_t(sizes_.cacheEntries);
  const ProbePushConstants cacheCheck = push(0, cacheEntries);
  const ProbePushConstants count = push(gpu_shared::kProbeSelectModeCount, probes);
  const ProbePushConstants emit = push(gpu_shared::kProbeSelectModeEmit, probes);
  const ProbePushConstants args = push(gpu_shared::kProbeSelectModeArgs, 1);
  const ProbePushConstants trace = push(0, capacity * settings_.raysPerProbe);
  const ProbePushConstants interior = push(0, capacity * gpu_shared::kProbeBlendThreadsPerProbe);

  batch.fill(statsBuffer_, 0u);
  batch.dispatch("probe_classify", classify_.get(corners), b, &classify, sizeof classify,
                 spread(probes));
  // Only frames whose windows scrolled or whose pages changed can invalidate cached rays.
  if (checksHitCache(lastFrame_.constants))
    batch.dispatch("probe_cache_check", cacheCheck_.get(corners), b, &cacheCheck, sizeof cacheCheck,
                   spread(cacheEntries));
  batch.dispatch("probe_select_count", select_.get(corners), b, &count, sizeof count,
                 spread(probes));
  batch.dispatch("probe_select_emit", select_.get(corners), b, &emit, sizeof emit, spread(probes));
  batch.dispatch("probe_select_args", select_.get(corners), b, &args, sizeof args, {1, 1, 1});
  // Sized on the GPU by the list's length: sleeping and off probes launch no thread at all.
  batch.dispatchIndirect("probe_trace", trace_.get(corners), b, &trace, sizeof trace, dispatchArgs_,
                         0);
  if (lastFrame_.constants.bounce.y > 0) {
    // Sized like the trace: each listed ray adds at most one cell and itself, and then itself
    // once more where its cell disagrees.
    ProbePushConstants cells = trace, waiting = trace, own = trace;
    cells.dispatch.x = gpu_shared::kProbeBounceModeCells;
    waiting.dispatch.x = gpu_shared::kProbeBounceModeRays;
    own.dispatch.x = gpu_shared::kProbeBounceModeOwn;
    batch.dispatchIndirect("probe_bounce_cells", bounce_.get(corners), b, &cells, sizeof cells,
                           dispatchArgs_, 0);
    batch.dispatchIndirect("probe_bounce_rays", bounce_.get(corners), b, &waiting, sizeof waiting,
                           dispatchArgs_, 0);
    batch.dispatchIndirect("probe_bounce_own", bounce_.get(corners), b, &own, sizeof own,
                           dispatchArgs_, 0);
  }
  batch.dispatchIndirect("probe_blend", blend_.get(corners), b, &interior, sizeof interior,
                         dispatchArgs_, 12);
  batch.copy(statsBuffer_, statsReadback_[staging.currentSlot()], gpu_shared::kProbeStatCount * 4);
}

ProbeFieldStats ProbeField::readStats(std::uint32_t slot) const {
  std::vector<std::uint32_t> raw(gpu_shared::kProbeStatCount);
  std::memcpy(raw.data(), statsReadback_.at(slot).mapped(), raw.size() * 4);
  return decodeStats(raw);
}

std::vector<glm::vec3> ProbeField::sample(const GpuStackScene& scene, const gpu::Buffer& light,
                                          std::span<const gpu_shared::ProbeQuery> queries) {
  if (queries.empty()) return {};
  const std::size_t qBytes = queries.size() * sizeof(gpu_shared::ProbeQuery);
  const std::size_t rBytes = queries.size() * sizeof(glm::vec4);
  queries_.reserve(qBytes);
  results_.reserve(rBytes);
  // Every earlier batch was waited for: the host-visible buffers are free to rewrite.
  std::memcpy(queries_.host(), queries.data(), qBytes);
  ProbePushConstants pc{};
  pc.dispatch = glm::uvec4(0u, std::uint32_t(queries.size()), 0u, 0u);
  gpu::CommandBatch batch = context_.beginBatch();
  queries_.recordCopy(batch, qBytes);
  batch.dispatch("probe_sample", sampleVariant(false), bindings(scene, light, true), &pc, sizeof pc,
                 spread(pc.dispatch.y));
  return finishSampling(batch, queries.size());
}

std::vector<glm::vec3> ProbeField::sampleHalfResolution(
    const GpuStackScene& scene, const gpu::Buffer& light,
    std::span<const gpu_shared::ProbeQuery> image, std::uint32_t width, std::uint32_t height,
    std::uint32_t blockSize) {
  if (blockSize != 2 && blockSize != 4)
    throw std::invalid_argument("ProbeField::sampleHalfResolution: block size " +
                                std::to_string(blockSize) + " (2 or 4)");
  if (std::size_t(width) * height != image.size())
    throw std::invalid_argument(
        "ProbeField::sampleHalfResolution: " + std::to_string(image.size()) + " queries for a " +
        std::to_string(width) + "x" + std::to_string(height) + " image");
  if (image.empty()) return {};
  const std::uint32_t lowWidth = (width + blockSize - 1) / blockSize;
  const std::uint32_t lowHeight = (height + blockSize - 1) / blockSize;
  const std::size_t qBytes = image.size() * sizeof(gpu_shared::ProbeQuery);
  const std::size_t rBytes = image.size() * sizeof(glm::vec4);
  const std::size_t lowBytes = std::size_t(lowWidth) * lowHeight * sizeof(glm::vec4);
  queries_.reserve(qBytes);
  results_.reserve(rBytes);
  if (!halfResults_ || halfResults_.size() < lowBytes)
    halfResults_ = deviceBuffer(context_, lowBytes);
  std::memcpy(queries_.host(), image.data(), qBytes);
  ProbePushConstants pc{};
  pc.dispatch =
      glm::uvec4(blockSize, halfResolutionInvocations(lowWidth, lowHeight), width, height);
  ProbePushConstants up{};
  up.dispatch = glm::uvec4(blockSize, std::uint32_t(image.size()), width, height);
  gpu::CommandBatch batch = context_.beginBatch();
  queries_.recordCopy(batch, qBytes);
  batch.dispatch("probe_sample", sampleVariant(true), bindings(scene, light, true, &halfResults_),
                 &pc, sizeof pc, spread(pc.dispatch.y));
  batch.dispatch("probe_upsample", upsample_,
                 {&queries_.device(), &halfResults_, &results_.device()}, &up, sizeof up,
                 spread(up.dispatch.y));
  return finishSampling(batch, image.size());
}

const gpu::ComputePipeline& ProbeField::sampleVariant(bool halfResolution) {
  return sample_.variant((halfResolution ? 1u : 0u) | (settings_.nearFieldRays > 0 ? 2u : 0u));
}

std::vector<glm::vec3> ProbeField::finishSampling(gpu::CommandBatch& batch, std::size_t count) {
  results_.recordCopy(batch, count * sizeof(glm::vec4));
  batch.submitAndWait();
  timings_ = batch.timings();
  std::vector<glm::vec3> out(count);
  const auto* r = static_cast<const glm::vec4*>(results_.host());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = glm::vec3(r[i]);
  return out;
}

double ProbeField::lastMilliseconds() const {
  double ms = 0.0;
  for (const auto& t : timings_) ms += t.milliseconds;
  return ms;
}

namespace {
template <typename T>
std::vector<T> download(const gpu::Buffer& b, std::size_t count) {
  std::vector<T> out(count);
  b.download(out.data(), count * sizeof(T));
  return out;
}
}  // namespace

std::vector<glm::vec4> ProbeField::downloadIrradiance() const {
  return download<glm::vec4>(irradiance_, sizes_.irradianceTexels);
}
std::vector<glm::vec2> ProbeField::downloadDepth() const {
  return download<glm::vec2>(depth_, sizes_.depthTexels);
}
std::vector<glm::vec4> ProbeField::downloadProbeData() const {
  return download<glm::vec4>(data_, sizes_.probes);
}
std::vector<glm::uvec2> ProbeField::downloadHitCache() const {
  return download<glm::uvec2>(cache_, sizes_.cacheEntries);
}
ProbeField::RayRecords ProbeField::downloadRays(std::uint32_t listed) const {
  const std::size_t n = std::min<std::size_t>(listed, settings_.listCapacity(cascades_));
  const std::size_t rays = n * settings_.raysPerProbe;
  return {download<std::uint32_t>(list_, n), download<glm::vec4>(rays_, rays),
          download<glm::vec4>(rayDirs_, rays)};
}

}  // namespace sdfstream::probe
