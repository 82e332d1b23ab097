#include "gi/gpu_tracer.h"

#include <cassert>

#include "gpu/command_batch.h"

namespace sdfstream {
namespace {
template <typename T>
gpu::Buffer deviceBufferWith(gpu::Context& ctx, const std::vector<T>& data) {
  gpu::Buffer b(ctx, data.size() * sizeof(T), gpu::BufferKind::DeviceLocal);
  b.upload(data.data(), data.size() * sizeof(T));
  return b;
}
}  // namespace

GpuTracer::GpuTracer(gpu::Context& context)
    : context_(context),
      batch_(context),
      pipeline_(
          context, gpu::ShaderId::trace_rays,
          gpu::PipelineDesc{6, sizeof(gpu_shared::TracePushConstants), glm::uvec3(64, 1, 1)}) {}

void GpuTracer::setCascade(const CascadeImage& cascade) {
  // Move-assignment hands the previous buffers to the deferred-deletion queue.
  pageTable_ = deviceBufferWith(context_, cascade.pageTable);
  distanceAtlas_ = deviceBufferWith(context_, cascade.distanceAtlas);
  albedoAtlas_ = deviceBufferWith(context_, cascade.albedoAtlas);
  emissionAtlas_ = deviceBufferWith(context_, cascade.emissionAtlas);
  toroidalOffset_ = cascade.toroidalOffset();
}

std::vector<gpu_shared::TraceHit> GpuTracer::trace(std::span<const gpu_shared::TraceRay> rays,
                                                   const TraceSettings& settings) {
  assert(pageTable_ && "setCascade() before trace()");
  if (rays.empty()) return {};
  batch_.stage(rays);

  gpu_shared::TracePushConstants pc{};
  pc.toroidalOffset = toroidalOffset_;
  pc.rayCount = std::uint32_t(rays.size());
  pc.maxSteps = settings.maxSteps;
  pc.hitEpsilon = settings.hitEpsilon;

  gpu::CommandBatch batch = context_.beginBatch();
  batch_.recordUpload(batch);
  batch.dispatch("trace", pipeline_,
                 {&batch_.rays(), &batch_.hits(), &pageTable_, &distanceAtlas_, &albedoAtlas_,
                  &emissionAtlas_},
                 &pc, sizeof pc, glm::uvec3(pc.rayCount, 1, 1));
  batch_.recordReadback(batch);
  batch.submitAndWait();
  timings_ = batch.timings();
  return batch_.readHits();
}

double GpuTracer::lastTraceMilliseconds() const {
  double ms = 0.0;
  for (const auto& t : timings_)
    if (t.name == "trace") ms += t.milliseconds;
  return ms;
}

}  // namespace sdfstream
