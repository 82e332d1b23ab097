#include "gi/gpu_stack_scene.h"

#include <algorithm>
#include <cstring>
#include <vector>

namespace sdfstream {
namespace {
constexpr std::size_t kDistWords = gpu_shared::kBrickDistanceWords;
constexpr std::size_t kMatWords = gpu_shared::kBrickMaterialCount;
constexpr std::size_t kCornerWords = gpu_shared::kBrickCornerWords;

void ensure(gpu::Context& ctx, gpu::Buffer& buffer, std::size_t bytes) {
  if (buffer.size() < bytes || !buffer)
    buffer = gpu::Buffer(ctx, bytes, gpu::BufferKind::DeviceLocal);
}

template <typename T>
std::size_t recordVector(gpu::Context& ctx, gpu::CommandBatch& batch, gpu::StagingRing& staging,
                         gpu::Buffer& buffer, const std::vector<T>& data) {
  const std::size_t bytes = data.size() * sizeof(T);
  ensure(ctx, buffer, bytes);
  staging.upload(batch, buffer, 0, data.data(), bytes);
  return bytes;
}

// The listed slots of one atlas array, packed into the staging ring and copied by one command.
std::size_t recordSlots(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                        const std::vector<std::uint32_t>& atlas, gpu::Buffer& dst,
                        std::size_t words, std::span<const std::uint32_t> slots) {
  const std::size_t bytes = words * 4;
  if (slots.empty()) return 0;
  const gpu::StagingRing::Reservation r = staging.reserve(slots.size() * bytes);
  std::vector<VkBufferCopy> regions;
  regions.reserve(slots.size());
  for (std::size_t i = 0; i < slots.size(); ++i) {
    std::memcpy(r.data + i * bytes, &atlas[std::size_t(slots[i]) * words], bytes);
    const VkBufferCopy c{r.offset + i * bytes, std::size_t(slots[i]) * bytes, bytes};
    // Runs of neighbouring slots are one region: a whole-atlas upload becomes a single copy
    // (the validation layer checks regions pairwise for overlap).
    if (!regions.empty() && regions.back().srcOffset + regions.back().size == c.srcOffset &&
        regions.back().dstOffset + regions.back().size == c.dstOffset)
      regions.back().size += bytes;
    else
      regions.push_back(c);
  }
  // At most kRegionsPerCopy regions per command, for the same reason: the layer's cost per
  // command grows with the square of its regions. At 256 a region it was 30 ms of a streaming
  // frame on lavapipe (the soak: 71 ms a frame validated, 38 without); at 32 the layer adds
  // ~2 ms and the frame is no slower unvalidated (4 a command was slower again: per-command cost).
  constexpr std::size_t kRegionsPerCopy = 32;
  for (std::size_t i = 0; i < regions.size(); i += kRegionsPerCopy)
    batch.copyRegions(*r.buffer, dst,
                      std::span(regions).subspan(i, std::min(kRegionsPerCopy, regions.size() - i)));
  return slots.size() * bytes;
}

// One blocking round: own batch, one-slot ring, submit and wait.
template <typename Record>
auto blocking(gpu::Context& ctx, Record&& record) {
  gpu::StagingRing staging(ctx, 1);
  gpu::CommandBatch batch = ctx.beginBatch(GpuStackScene::kUploadPasses);
  staging.beginFrame();
  auto result = record(batch, staging);
  staging.endFrame(batch.submit());
  batch.wait();
  return result;
}
}  // namespace

std::size_t GpuStackScene::recordUploadAll(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                                           const CascadeStackImage& image) {
  cascadeCount_ = std::uint32_t(image.params.size());
  slotCount_ = std::uint32_t(image.distanceAtlas->size() / kDistWords);
  std::size_t bytes = recordVector(context_, batch, staging, pageTables_, image.pageTables);
  bytes += recordVector(context_, batch, staging, params_, image.params);
  bytes += recordVector(context_, batch, staging, distance_, *image.distanceAtlas);
  bytes += recordVector(context_, batch, staging, albedo_, *image.albedoAtlas);
  bytes += recordVector(context_, batch, staging, emission_, *image.emissionAtlas);
  ensureCorners(slotCount_);
  recordCorners(batch, staging, {}, true);
  return bytes;
}

void GpuStackScene::ensureCorners(std::uint32_t slots) {
  const std::size_t bytes = std::max<std::size_t>(slots, 1) * kCornerWords * 4;
  if (!cornersWanted_ || bytes > context_.properties().limits.maxStorageBufferRange) {
    corners_ = gpu::Buffer();
    cornersOn_ = false;
    return;
  }
  cornersOn_ = true;
  if (corners_ && corners_.size() >= bytes) return;
  try {
    corners_ = gpu::Buffer(context_, bytes, gpu::BufferKind::DeviceLocal);
  } catch (const gpu::OutOfDeviceMemory&) {
    // The traces read the distance atlas from now on: a corner atlas allocated later would hold
    // nothing for the slots already uploaded.
    corners_ = gpu::Buffer();
    cornersOn_ = false;
    cornersWanted_ = false;
  }
}

void GpuStackScene::recordCorners(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                                  std::span<const std::uint32_t> slots, bool all) {
  const std::uint32_t count = all ? slotCount_ : std::uint32_t(slots.size());
  if (!cornersOn_ || count == 0) return;
  if (!cornersPipeline_)
    cornersPipeline_ = gpu::ComputePipeline(
        context_, gpu::ShaderId::brick_corners,
        gpu::PipelineDesc{3, sizeof(gpu_shared::BrickCornersPush), glm::uvec3(64, 1, 1)});
  ensure(context_, cornerSlots_, std::max<std::size_t>(slots.size(), 1) * 4);
  if (!all) staging.upload(batch, cornerSlots_, 0, slots.data(), slots.size_bytes());
  const gpu_shared::BrickCornersPush push{count, all ? 0u : 1u, 0, 0};
  batch.dispatch("brick_corners", cornersPipeline_, {&cornerSlots_, &distance_, &corners_}, &push,
                 sizeof push, gpu::spreadOverRows(count * std::uint32_t(kMatWords)));
}

void GpuStackScene::releaseAtlas() {
  distance_ = gpu::Buffer();
  albedo_ = gpu::Buffer();
  emission_ = gpu::Buffer();
  corners_ = gpu::Buffer();
}

std::uint32_t GpuStackScene::reserveAtlas(std::uint32_t slots) {
  constexpr std::uint32_t kMinSlots = 64;
  for (;;) {
    try {
      ensure(context_, distance_, std::size_t(slots) * kDistWords * 4);
      ensure(context_, albedo_, std::size_t(slots) * kMatWords * 4);
      ensure(context_, emission_, std::size_t(slots) * kMatWords * 4);
      ensureCorners(slots);  // drops the corners rather than halving the slots
      slotCap_ = slots;
      return slots;
    } catch (const gpu::OutOfDeviceMemory&) {
      if (slots / 2 < kMinSlots) throw;
      slots /= 2;
      releaseAtlas();
    }
  }
}

std::uint32_t GpuStackScene::shrinkAtlas(std::uint32_t slots) {
  releaseAtlas();
  return reserveAtlas(slots);
}

std::size_t GpuStackScene::recordSync(gpu::CommandBatch& batch, gpu::StagingRing& staging,
                                      const CascadeStack& stack,
                                      std::span<const std::uint32_t> dirty) {
  const CascadeStackImage img = stack.stackImage();
  cascadeCount_ = std::uint32_t(img.params.size());
  slotCount_ = std::uint32_t(stack.atlasDistance().size() / kDistWords);
  if (slotCap_ && slotCount_ > slotCap_) slotCount_ = slotCap_;  // the stack keeps below the cap
  ensure(context_, distance_, std::size_t(slotCount_) * kDistWords * 4);
  ensure(context_, albedo_, std::size_t(slotCount_) * kMatWords * 4);
  ensure(context_, emission_, std::size_t(slotCount_) * kMatWords * 4);
  std::size_t bytes = recordVector(context_, batch, staging, pageTables_, img.pageTables);
  bytes += recordVector(context_, batch, staging, params_, img.params);
  bytes += recordSlots(batch, staging, stack.atlasDistance(), distance_, kDistWords, dirty);
  bytes += recordSlots(batch, staging, stack.atlasAlbedo(), albedo_, kMatWords, dirty);
  bytes += recordSlots(batch, staging, stack.atlasEmission(), emission_, kMatWords, dirty);
  ensureCorners(slotCount_);
  recordCorners(batch, staging, dirty, false);
  return bytes;
}

void GpuStackScene::uploadAll(const CascadeStackImage& image) {
  blocking(context_,
           [&](gpu::CommandBatch& b, gpu::StagingRing& s) { return recordUploadAll(b, s, image); });
}

std::size_t GpuStackScene::sync(const CascadeStack& stack, std::span<const std::uint32_t> dirty) {
  return blocking(context_, [&](gpu::CommandBatch& b, gpu::StagingRing& s) {
    return recordSync(b, s, stack, dirty);
  });
}

}  // namespace sdfstream
