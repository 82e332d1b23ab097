// The trace pass on the GPU: uploads a cascade image and runs trace_rays.comp over a batch of
// rays. Same inputs and outputs as traceRaysCpu (gi/cpu_tracer.h), which is its test oracle.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "gi/cpu_tracer.h"
#include "gi/ray_batch.h"
#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/context.h"

namespace sdfstream {

class GpuTracer {
 public:
  explicit GpuTracer(gpu::Context& context);

  // Uploads page table and atlas (replacing the previous cascade; the old buffers are freed once
  // the GPU is done with them).
  void setCascade(const CascadeImage& cascade);

  // Traces the rays; blocks until the results are back. Per-pass GPU times of this call are in
  // lastTimings() ("trace" is the shader itself).
  std::vector<gpu_shared::TraceHit> trace(std::span<const gpu_shared::TraceRay> rays,
                                          const TraceSettings& settings);
  const std::vector<gpu::PassTiming>& lastTimings() const { return timings_; }
  double lastTraceMilliseconds() const;

 private:
  gpu::Context& context_;
  RayBatch batch_;
  gpu::ComputePipeline pipeline_;
  gpu::Buffer pageTable_, distanceAtlas_, albedoAtlas_, emissionAtlas_;
  glm::uvec4 toroidalOffset_{0};
  std::vector<gpu::PassTiming> timings_;
};

}  // namespace sdfstream
