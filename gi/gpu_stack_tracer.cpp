#include "gi/gpu_stack_tracer.h"

#include <stdexcept>
#include <string>

namespace sdfstream {
GpuStackTracer::GpuStackTracer(gpu::Context& context, const CascadeStack& stack, bool cellCorners)
    : context_(context),
      batch_(context),
      pipeline_(
          context, gpu::ShaderId::trace_stack,
          gpu::PipelineDesc{7, sizeof(gpu_shared::TraceStackPushConstants), glm::uvec3(64, 1, 1)}),
      scene_(context, cellCorners) {
  scene_.sync(stack, {});
  pipeline_.get(scene_.cellCorners());  // compiled here, not in the first trace
}

std::vector<gpu_shared::TraceHit> GpuStackTracer::trace(std::span<const gpu_shared::TraceRay> rays,
                                                        const TraceSettings& settings,
                                                        std::uint32_t dispatches) {
  if (settings.visibilityRule)
    throw std::invalid_argument("GpuStackTracer traces exactly; the visibility rule is sampling's");
  if (settings.descend)
    throw std::invalid_argument(
        "GpuStackTracer traces as probe rays do; camera rays descend in the shading pass");
  if (dispatches < 1 || dispatches > 60)
    throw std::invalid_argument("GpuStackTracer::trace: " + std::to_string(dispatches) +
                                " dispatches (1..60)");
  if (rays.empty()) return {};
  batch_.stage(rays);
  gpu_shared::TraceStackPushConstants pc{
      std::uint32_t(rays.size()), settings.maxSteps,     settings.hitEpsilon,
      scene_.cascadeCount(),      settings.firstCascade, scene_.cellCorners() ? 1u : 0u};
  gpu::CommandBatch batch = context_.beginBatch();
  batch_.recordUpload(batch);
  for (std::uint32_t d = 0; d < dispatches; ++d)
    batch.dispatch("trace_stack", pipeline_.get(scene_.cellCorners()),
                   {&batch_.rays(), &batch_.hits(), &scene_.pageTables(), &scene_.traceAtlas(),
                    &scene_.albedo(), &scene_.emission(), &scene_.params()},
                   &pc, sizeof pc, glm::uvec3(pc.rayCount, 1, 1));
  batch_.recordReadback(batch);
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
