#include "gi/gpu_stack_scene.h"

#include <cstring>
#include <vector>

#include "gpu/command_batch.h"

namespace sdfstream {
namespace {
constexpr std::size_t kDistBytes = gpu_shared::kBrickDistanceWords * 4;
constexpr std::size_t kMatBytes = gpu_shared::kBrickMaterialCount * 4;

void ensure(gpu::Context& ctx, gpu::Buffer& buffer, std::size_t bytes) {
  if (buffer.size() < bytes || !buffer) buffer = gpu::Buffer(ctx, bytes, gpu::BufferKind::DeviceLocal);
}

template <typename T>
void uploadVector(gpu::Context& ctx, gpu::Buffer& buffer, const std::vector<T>& data) {
  const std::size_t bytes = data.size() * sizeof(T);
  ensure(ctx, buffer, bytes);
  if (bytes) buffer.upload(data.data(), bytes);
}
}  // namespace

void GpuStackScene::uploadAll(const CascadeStackImage& image) {
  cascadeCount_ = std::uint32_t(image.params.size());
  slotCount_ = std::uint32_t(image.distanceAtlas->size() / gpu_shared::kBrickDistanceWords);
  uploadVector(context_, pageTables_, image.pageTables);
  uploadVector(context_, params_, image.params);
  uploadVector(context_, distance_, *image.distanceAtlas);
  uploadVector(context_, albedo_, *image.albedoAtlas);
  uploadVector(context_, emission_, *image.emissionAtlas);
}

std::size_t GpuStackScene::sync(const CascadeStack& stack, std::span<const std::uint32_t> dirty) {
  const CascadeStackImage img = stack.stackImage();
  cascadeCount_ = std::uint32_t(img.params.size());
  slotCount_ = std::uint32_t(stack.atlasDistance().size() / gpu_shared::kBrickDistanceWords);
  ensure(context_, pageTables_, img.pageTables.size() * 4);
  ensure(context_, params_, img.params.size() * sizeof(gpu_shared::CascadeTraceParams));
  ensure(context_, distance_, stack.atlasDistance().size() * 4);
  ensure(context_, albedo_, stack.atlasAlbedo().size() * 4);
  ensure(context_, emission_, stack.atlasEmission().size() * 4);

  const std::size_t tableBytes = img.pageTables.size() * 4;
  const std::size_t paramBytes = img.params.size() * sizeof(gpu_shared::CascadeTraceParams);
  const std::size_t perSlot = kDistBytes + 2 * kMatBytes;
  const std::size_t total = tableBytes + paramBytes + dirty.size() * perSlot;
  if (staging_.size() < total) staging_ = gpu::Buffer(context_, total, gpu::BufferKind::Upload);
  // Every earlier batch was waited for, so the staging buffer is free to overwrite.
  auto* base = static_cast<std::uint8_t*>(staging_.mapped());
  std::memcpy(base, img.pageTables.data(), tableBytes);
  std::memcpy(base + tableBytes, img.params.data(), paramBytes);
  gpu::CommandBatch batch = context_.beginBatch();
  batch.copy(staging_, pageTables_, tableBytes, 0, 0);
  batch.copy(staging_, params_, paramBytes, tableBytes, 0);
  std::size_t offset = tableBytes + paramBytes;
  // One copy per dirty slot and array; slots are sorted, runs of neighbours could be merged
  // later if the command count ever shows up in the timings.
  auto copySlot = [&](const std::vector<std::uint32_t>& src, gpu::Buffer& dst, std::size_t words,
                      std::uint32_t slot) {
    const std::size_t bytes = words * 4;
    std::memcpy(base + offset, &src[std::size_t(slot) * words], bytes);
    batch.copy(staging_, dst, bytes, offset, std::size_t(slot) * bytes);
    offset += bytes;
  };
  for (std::uint32_t slot : dirty) {
    copySlot(stack.atlasDistance(), distance_, gpu_shared::kBrickDistanceWords, slot);
    copySlot(stack.atlasAlbedo(), albedo_, gpu_shared::kBrickMaterialCount, slot);
    copySlot(stack.atlasEmission(), emission_, gpu_shared::kBrickMaterialCount, slot);
  }
  batch.submitAndWait();
  return total;
}

}  // namespace sdfstream
