#include "gi/gpu_stack_tracer.h"

#include <cstring>

namespace sdfstream {
namespace {
constexpr std::size_t kDistBytes = layout::kBrickDistanceWords * 4;
constexpr std::size_t kMatBytes = layout::kBrickMaterialCount * 4;
}  // namespace

GpuStackTracer::GpuStackTracer(gpu::Context& context, const CascadeStack& stack)
    : context_(context),
      batch_(context),
      pipeline_(context, gpu::ShaderId::trace_stack,
                gpu::PipelineDesc{7, sizeof(gpu_shared::TraceStackPushConstants), glm::uvec3(64, 1, 1)}),
      cascadeCount_(std::uint32_t(stack.cascadeCount())),
      pageTables_(context, std::size_t(cascadeCount_) * layout::kCascadePageCount * 4,
                  gpu::BufferKind::DeviceLocal),
      distance_(context, stack.atlasDistance().size() * 4, gpu::BufferKind::DeviceLocal),
      albedo_(context, stack.atlasAlbedo().size() * 4, gpu::BufferKind::DeviceLocal),
      emission_(context, stack.atlasEmission().size() * 4, gpu::BufferKind::DeviceLocal),
      params_(context, cascadeCount_ * sizeof(gpu_shared::CascadeTraceParams),
              gpu::BufferKind::DeviceLocal) {}

std::size_t GpuStackTracer::sync(const CascadeStack& stack, std::span<const std::uint32_t> dirty) {
  CascadeStackImage img = stack.stackImage();
  const std::size_t tableBytes = img.pageTables.size() * 4;
  const std::size_t paramBytes = img.params.size() * sizeof(gpu_shared::CascadeTraceParams);
  const std::size_t perSlot = kDistBytes + 2 * kMatBytes;
  const std::size_t total = tableBytes + paramBytes + dirty.size() * perSlot;
  if (staging_.size() < total) staging_ = gpu::Buffer(context_, total, gpu::BufferKind::Upload);
  // The previous frame's batch was waited for, so the staging buffer is free to overwrite.
  auto* base = static_cast<std::uint8_t*>(staging_.mapped());
  std::memcpy(base, img.pageTables.data(), tableBytes);
  std::memcpy(base + tableBytes, img.params.data(), paramBytes);
  gpu::CommandBatch batch = context_.beginBatch();
  batch.copy(staging_, pageTables_, tableBytes, 0, 0);
  batch.copy(staging_, params_, paramBytes, tableBytes, 0);
  std::size_t offset = tableBytes + paramBytes;
  // One copy per dirty slot and array; slots are sorted, runs of neighbours could be merged
  // later if the command count ever shows up in the timings.
  for (std::uint32_t slot : dirty) {
    std::memcpy(base + offset, &stack.atlasDistance()[std::size_t(slot) * layout::kBrickDistanceWords], kDistBytes);
    batch.copy(staging_, distance_, kDistBytes, offset, std::size_t(slot) * kDistBytes);
    offset += kDistBytes;
    std::memcpy(base + offset, &stack.atlasAlbedo()[std::size_t(slot) * layout::kBrickMaterialCount], kMatBytes);
    batch.copy(staging_, albedo_, kMatBytes, offset, std::size_t(slot) * kMatBytes);
    offset += kMatBytes;
    std::memcpy(base + offset, &stack.atlasEmission()[std::size_t(slot) * layout::kBrickMaterialCount], kMatBytes);
    batch.copy(staging_, emission_, kMatBytes, offset, std::size_t(slot) * kMatBytes);
    offset += kMatBytes;
  }
  batch.submitAndWait();
  return total;
}

std::vector<gpu_shared::TraceHit> GpuStackTracer::trace(std::span<const gpu_shared::TraceRay> rays,
                                                        const TraceSettings& settings) {
  if (rays.empty()) return {};
  batch_.stage(rays);
  gpu_shared::TraceStackPushConstants pc{std::uint32_t(rays.size()), settings.maxSteps,
                                         settings.hitEpsilon, cascadeCount_};
  gpu::CommandBatch batch = context_.beginBatch();
  batch.dispatch("trace_stack", pipeline_,
                 {&batch_.rays(), &batch_.hits(), &pageTables_, &distance_, &albedo_, &emission_, &params_}, &pc,
                 sizeof pc, glm::uvec3(pc.rayCount, 1, 1));
  batch.submitAndWait();
  timings_ = batch.timings();
  return batch_.readHits();
}

double GpuStackTracer::lastMilliseconds(const std::string& pass) const {
  double ms = 0.0;
  for (const auto& t : timings_)
    if (t.name == pass) ms += t.milliseconds;
  return ms;
}

}  // namespace sdfstream
