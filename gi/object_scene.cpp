#include "gi/object_scene.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include <tbb/task_group.h>

#include "core/stopwatch.h"

#include "shaders/shared/sdf_layout.h"

namespace sdfstream {
namespace gs = gpu_shared;
namespace {
constexpr glm::uvec3 kGroup(64, 1, 1);

// Grows a buffer to at least `bytes` (contents not kept).
void ensure(gpu::Context& ctx, gpu::Buffer& b, std::size_t bytes, gpu::BufferKind kind) {
  if (b.size() < bytes) b = gpu::Buffer(ctx, std::max<std::size_t>(bytes, 4), kind);
}
}  // namespace

NoObjectsBindings::NoObjectsBindings(gpu::Context& context)
    : meta_(context, sizeof(gs::ObjectFrameGpu) + sizeof(gs::ObjectMeshGpu),
            gpu::BufferKind::Upload),
      empty_(context, 64, gpu::BufferKind::DeviceLocal) {
  std::memset(meta_.mapped(), 0, meta_.size());
}

ObjectScene::ObjectScene(gpu::Context& context, ObjectSceneSettings settings)
    : context_(context),
      settings_(settings),
      regionsPipeline_(context, gpu::ShaderId::object_regions,
                       gpu::PipelineDesc{8, sizeof(gs::ObjectRegionPush), kGroup}),
      scanPipeline_(context, gpu::ShaderId::object_regions_scan,
                    gpu::PipelineDesc{8, sizeof(gs::ObjectRegionPush),
                                      glm::uvec3(gs::kRegionScanThreads, 1, 1)}),
      tracePipeline_(context, gpu::ShaderId::object_trace,
                     gpu::PipelineDesc{10, sizeof(gs::ObjectTracePush), kGroup}),
      meta_(context, sizeof(gs::ObjectFrameGpu) + sizeof(gs::ObjectMeshGpu),
            gpu::BufferKind::DeviceLocal),
      instances_(context, sizeof(gs::ObjectInstanceGpu), gpu::BufferKind::DeviceLocal),
      regions_(context, sizeof(gs::ObjectRegionGpu), gpu::BufferKind::DeviceLocal),
      lists_(context, 4, gpu::BufferKind::DeviceLocal),
      distance_(context, 4, gpu::BufferKind::DeviceLocal),
      material_(context, 8, gpu::BufferKind::DeviceLocal),
      cardData_(context, 64, gpu::BufferKind::DeviceLocal),
      cardLight_(context, 4, gpu::BufferKind::DeviceLocal),
      relightList_(context, 4, gpu::BufferKind::DeviceLocal),
      cardNonFinite_(context, 4, gpu::BufferKind::DeviceLocal) {
  // Inactive until the first update: the meta buffer must still read as "no instances".
  gpu::CommandBatch batch = context.beginBatch(0);
  batch.fill(meta_, 0u);
  batch.fill(cardNonFinite_, 0u);
  batch.submitAndWait();
}

void ObjectScene::recordAtlas(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                              const ObjectLibrary& library) {
  ObjectAtlasData atlas = buildObjectAtlas(library);
  meshes_ = std::move(atlas.meshes);
  const std::size_t distBytes = atlas.distance.size() * sizeof(float);
  const std::size_t matBytes = atlas.material.size() * sizeof(glm::uvec2);
  distance_ =
      gpu::Buffer(context_, std::max<std::size_t>(distBytes, 4), gpu::BufferKind::DeviceLocal);
  material_ =
      gpu::Buffer(context_, std::max<std::size_t>(matBytes, 8), gpu::BufferKind::DeviceLocal);
  staging.upload(batch, distance_, 0, atlas.distance.data(), distBytes);
  staging.upload(batch, material_, 0, atlas.material.data(), matBytes);
  atlasVersion_ = library.version();
}

void ObjectScene::prepareCards(const ObjectLibrary& library, double voxelSize0) {
  if (cardsVersion_ == library.version()) return;
  // Texels of about one cascade-0 voxel (world units = object units at scale 1), never finer
  // than the object's SDF: unknown until a stack is seen, unless the settings fix it.
  const double texelWorld = settings_.cardTexelWorld > 0.0 ? settings_.cardTexelWorld : voxelSize0;
  if (!(texelWorld > 0.0)) return;
  cardsVersion_ = library.version();
  cardsUploaded_ = false;
  captureMilliseconds_ = 0.0;
  // The library only appends meshes: those captured before at the same texel size keep their
  // cards; only the new ones are captured.
  std::uint32_t done = texelWorld == cardsTexelWorld_ ? capturedMeshes_ : 0u;
  if (done == 0) cardTexels_.clear();
  cardsTexelWorld_ = texelWorld;
  const std::uint32_t meshes = std::uint32_t(library.size());
  meshTexels_.resize(meshes, 0u);
  meshLevelTexels_.resize(std::size_t(meshes) * gs::kCardLightLevels, 0u);
  cardTable_.resize(std::size_t(meshes) * gs::kCardsPerMesh, gs::CardGpu{});
  if (settings_.cards && !rasterizer_) {
    try {
      rasterizer_ = std::make_unique<CardRasterizer>(context_);
    } catch (const std::runtime_error& e) {  // e.g. a compute-only queue adopted from an engine
      std::fprintf(stderr, "sdfstream: moving objects without cards: %s\n", e.what());
      settings_.cards = false;
    }
  }
  // Texels are indexed from the start of the uvec4 array, after the table (4 uvec4 per card):
  // the cards kept move by as much as the table grew.
  const std::uint32_t tableWords = std::uint32_t(cardTable_.size()) * 4u;
  const std::uint32_t grown = tableWords - done * gs::kCardsPerMesh * 4u;
  for (std::uint32_t k = 0; k < done * gs::kCardsPerMesh; ++k) cardTable_[k].first.y += grown;
  capturedMeshes_ = settings_.cards ? meshes : 0u;
  for (std::uint32_t m = done; settings_.cards && m < meshes; ++m) {
    const ObjectSdf& sdf = library.mesh(m);
    const TriangleScene& triangles = library.triangles(m);
    const MeshCards cards = layoutCards(
        sdf.meshMin, sdf.meshMax, std::max(sdf.voxel, float(texelWorld)), settings_.cardLayout);
    const std::vector<CardVisibility> seen = rasterizer_->capture(triangles, cards);
    captureMilliseconds_ += rasterizer_->lastMilliseconds();
    const std::vector<gs::CardTexelGpu> texels = resolveCardTexels(triangles, cards, seen);
    const std::uint32_t first = tableWords + std::uint32_t(cardTexels_.size());
    for (std::uint32_t k = 0; k < gs::kCardsPerMesh; ++k) {
      gs::CardGpu c = cards.cards[k];
      c.first.y = first;
      cardTable_[m * gs::kCardsPerMesh + k] = c;
      maxCardTexels_ = std::max(maxCardTexels_, c.info.z * c.info.w);
    }
    cardTexels_.insert(cardTexels_.end(), texels.begin(), texels.end());
    meshTexels_[m] = cards.texelCount;
    for (std::uint32_t l = 0; l < gs::kCardLightLevels; ++l)
      meshLevelTexels_[m * gs::kCardLightLevels + l] = cards.lightTexels[l];
  }
}

void ObjectScene::uploadCards(gpu::CommandBatch& batch, gpu::StagingRing& staging) {
  cardsUploaded_ = true;
  static_assert(sizeof(gs::CardGpu) == 4 * sizeof(glm::uvec4) &&
                sizeof(gs::CardTexelGpu) == sizeof(glm::uvec4));
  const std::size_t tableBytes = cardTable_.size() * sizeof(gs::CardGpu);
  const std::size_t texelBytes = cardTexels_.size() * sizeof(gs::CardTexelGpu);
  cardData_ = gpu::Buffer(context_, std::max<std::size_t>(tableBytes + texelBytes, 64),
                          gpu::BufferKind::DeviceLocal);
  staging.upload(batch, cardData_, 0, cardTable_.data(), tableBytes);
  staging.upload(batch, cardData_, tableBytes, cardTexels_.data(), texelBytes);
}

void ObjectScene::recordCardLight(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                                  bool lightsChanged, glm::vec3 viewer, float levelBeyond) {
  relight_.clear();
  if (!settings_.cards) {
    for (gs::ObjectInstanceGpu& inst : frame_.instances) inst.info.w = gs::kNoCardLight;
    return;
  }
  CardLightLevels levels;
  levels.texels = meshLevelTexels_;
  levels.beyond = levelBeyond;
  relight_ = slots_.assign(frame_.instances, meshTexels_, lightsChanged,
                           settings_.cardRelightBudget, settings_.cardLightBudgetBytes / 4, viewer,
                           settings_.cardRelightTexelBudget, levels);
  const std::size_t needed = std::size_t(slots_.endTexel()) * sizeof(std::uint32_t);
  if (cardLight_.size() < needed) {
    // Grow by half again at least; blocks already lit keep their light.
    gpu::Buffer bigger(context_, std::max(needed, cardLight_.size() * 3 / 2),
                       gpu::BufferKind::DeviceLocal);
    batch.fill(bigger, 0u);
    batch.copy(cardLight_, bigger, cardLight_.size());
    cardLight_ = std::move(bigger);
  }
  if (relight_.empty()) return;
  ensure(context_, relightList_, relight_.size() * sizeof(std::uint32_t),
         gpu::BufferKind::DeviceLocal);
  staging.upload(batch, relightList_, 0, relight_.data(), relight_.size() * sizeof(std::uint32_t));
}

std::vector<std::uint32_t> ObjectScene::downloadCardLight() const {
  std::vector<std::uint32_t> out(slots_.endTexel());
  if (!out.empty()) cardLight_.download(out.data(), out.size() * sizeof(std::uint32_t));
  return out;
}

std::uint64_t ObjectScene::cardNonFiniteTexels() const {
  std::uint32_t n = 0;
  cardNonFinite_.download(&n, sizeof n);
  return n;
}

void ObjectScene::update(const ObjectLibrary& library, const InstanceSet& instances,
                         const CascadeStackImage& stack) {
  prepareCards(library, stack.voxelSize0);  // its own submission, before this batch opens
  gpu::StagingRing staging(context_, 1);
  gpu::CommandBatch batch = context_.beginBatch(kRegionPasses);
  staging.beginFrame();
  record(batch, staging, library, instances, stack);
  staging.endFrame(batch.submit());
  batch.wait();
  timings_ = batch.timings();
}

namespace {
// Runs work on a worker thread from start() on; the destructor waits, so an exception on the
// calling thread cannot leave the task running; wait() rethrows what the work threw.
class Alongside {
 public:
  void start(const std::function<void()>& work) {
    if (work) group_.run(work);
  }
  ~Alongside() {
    try {
      group_.wait();
    } catch (...) {  // already unwinding, or wait() reported it
    }
  }
  void wait() { group_.wait(); }

 private:
  tbb::task_group group_;
};
}  // namespace

void ObjectScene::record(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                         const ObjectLibrary& library, const InstanceSet& instances,
                         const CascadeStackImage& stack, bool lightsChanged,
                         const std::function<void()>& alongside) {
  if (library.version() != atlasVersion_) recordAtlas(batch, staging, library);
  if (!cardsUploaded_) uploadCards(batch, staging);
  const auto buildStart = std::chrono::steady_clock::now();
  // The work alongside starts as soon as the changed boxes are known, while the instances and
  // the wake bits are still being built.
  Alongside other;
  buildObjectFrame(library, instances, stack, settings_, frame_, [&] { other.start(alongside); });
  recordBuilt(batch, staging, lightsChanged, stack, buildStart);
  other.wait();
}

void ObjectScene::recordBuilt(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                              bool lightsChanged, const CascadeStackImage& stack,
                              std::chrono::steady_clock::time_point buildStart) {
  // The viewer for the cards' eviction order and light levels: cascade 0's centre (the stack is
  // camera-centred). Instances beyond cascade 0's half extent are seen by cascade 1's probes and
  // coarser (2 voxels and more), so their light is kept at level 1, beyond twice that at level 2.
  glm::vec3 viewer(0.0f);
  float levelBeyond = 0.0f;
  if (!stack.params.empty()) {
    const float halfExtent = 0.5f * float(gs::kCascadeCells) * stack.params[0].offsetScale.w;
    viewer = glm::vec3(stack.params[0].offsetScale) + halfExtent;
    levelBeyond = std::max(settings_.cardLevelDistance, 0.0f) * halfExtent;
  }
  const auto cardsStart = std::chrono::steady_clock::now();
  recordCardLight(batch, staging, lightsChanged, viewer, levelBeyond);
  cardsMilliseconds_ = millisecondsSince(cardsStart);
  buildMilliseconds_ = millisecondsSince(buildStart);
  timings_.clear();

  const std::size_t metaBytes =
      sizeof(gs::ObjectFrameGpu) + meshes_.size() * sizeof(gs::ObjectMeshGpu);
  ensure(context_, meta_, metaBytes, gpu::BufferKind::DeviceLocal);
  staging.upload(batch, meta_, 0, &frame_.frame, sizeof(gs::ObjectFrameGpu));
  staging.upload(batch, meta_, sizeof(gs::ObjectFrameGpu), meshes_.data(),
                 meshes_.size() * sizeof(gs::ObjectMeshGpu));
  if (!active()) return;  // nothing to list: no pass at all

  const std::size_t instBytes = frame_.instances.size() * sizeof(gs::ObjectInstanceGpu);
  ensure(context_, instances_, instBytes, gpu::BufferKind::DeviceLocal);
  staging.upload(batch, instances_, 0, frame_.instances.data(), instBytes);
  const std::size_t regionBytes = frame_.regions.size() * sizeof(gs::ObjectRegionGpu);
  ensure(context_, regions_, regionBytes, gpu::BufferKind::DeviceLocal);
  staging.upload(batch, regions_, 0, frame_.regions.data(), regionBytes);
  ensure(context_, lists_, listEntries() * sizeof(glm::uvec4), gpu::BufferKind::DeviceLocal);

  const std::uint32_t n = frame_.frame.counts.x, cascades = frame_.frame.counts.y;
  if (n == 0) return;  // only removals: the moved flags, no lists to build
  const auto bufs = buffers();
  // The sub-cell headers start at zero (the sub-cell count phase adds into them).
  const bool subLists = frame_.subListCapacity > 0;
  if (subLists)
    batch.fill(lists_, 0u, std::size_t(frame_.listCapacity) * sizeof(glm::uvec4),
               std::size_t(frame_.subListCapacity) * sizeof(glm::uvec4));
  gs::ObjectRegionPush push{0u, n,  cascades, frame_.listCapacity, frame_.subListCapacity,
                            0u, 0u, 0u};
  const glm::uvec3 perInstance(64u * n, cascades, 1u);
  if (!subLists) {  // the host placed the lists (ObjectRegionGpu::slots): one pass fills them
    push.phase = 6u;
    batch.dispatch("object_regions_fill", regionsPipeline_, bufs, &push, sizeof push, perInstance);
    return;
  }
  batch.dispatch("object_regions_count", regionsPipeline_, bufs, &push, sizeof push, perInstance);
  push.phase = 1u;
  const std::uint32_t regions = cascades * gs::kRegionsPerCascade;
  batch.dispatch("object_regions_rank", regionsPipeline_, bufs, &push, sizeof push,
                 glm::uvec3(regions, 1u, 1u));
  push.phase = 2u;
  batch.dispatch("object_regions_scan", scanPipeline_, bufs, &push, sizeof push,
                 glm::uvec3(gs::kRegionScanThreads, 1u, 1u));
  push.phase = 3u;
  batch.dispatch("object_regions_subcount", regionsPipeline_, bufs, &push, sizeof push,
                 perInstance);
  push.phase = 4u;
  batch.dispatch("object_regions_subscan", regionsPipeline_, bufs, &push, sizeof push,
                 glm::uvec3(64u * regions, 1u, 1u));
  push.phase = 5u;
  batch.dispatch("object_regions_fill", regionsPipeline_, bufs, &push, sizeof push, perInstance);
}

std::size_t ObjectScene::listEntries() const {
  return std::size_t(frame_.listCapacity) + 2 * std::size_t(frame_.subListCapacity);
}

std::vector<gs::ObjectTraceHit> ObjectScene::trace(std::span<const gs::TraceRay> rays,
                                                   bool bruteForce) {
  std::vector<gs::ObjectTraceHit> hits(rays.size());
  traceTimings_.clear();
  if (rays.empty()) return hits;
  ensure(context_, rays_, rays.size_bytes(), gpu::BufferKind::Upload);
  ensure(context_, hits_, hits.size() * sizeof(gs::ObjectTraceHit), gpu::BufferKind::Readback);
  std::memcpy(rays_.mapped(), rays.data(), rays.size_bytes());
  const gs::ObjectTracePush push{std::uint32_t(rays.size()), bruteForce ? 1u : 0u, 0u, 0u};
  const std::array<const gpu::Buffer*, 10> bufs = {&meta_,     &instances_, &regions_,  &lists_,
                                                   &distance_, &material_,  &cardData_, &cardLight_,
                                                   &rays_,     &hits_};
  gpu::CommandBatch batch = context_.beginBatch(1);
  batch.dispatch(bruteForce ? "object_trace_all" : "object_trace_regions", tracePipeline_, bufs,
                 &push, sizeof push, glm::uvec3(std::uint32_t(rays.size()), 1u, 1u));
  batch.submitAndWait();
  traceTimings_ = batch.timings();
  std::memcpy(hits.data(), hits_.mapped(), hits.size() * sizeof(gs::ObjectTraceHit));
  return hits;
}

std::vector<gs::ObjectRegionGpu> ObjectScene::downloadRegions() const {
  std::vector<gs::ObjectRegionGpu> out(frame_.regions.size());
  if (!out.empty() && active()) regions_.download(out.data(), out.size() * sizeof out[0]);
  return out;
}

std::vector<glm::uvec4> ObjectScene::downloadLists() const {
  std::vector<glm::uvec4> out(active() ? listEntries() : 0);
  if (!out.empty()) lists_.download(out.data(), out.size() * sizeof(glm::uvec4));
  return out;
}

std::size_t ObjectScene::deviceBytes() const {
  return meta_.size() + instances_.size() + regions_.size() + lists_.size() + distance_.size() +
         material_.size() + cardData_.size() + cardLight_.size() + relightList_.size();
}

}  // namespace sdfstream
