// The stack traversal on the GPU (trace_stack.comp), fed by a streaming CascadeStack through a
// GpuStackScene: per frame only the page tables (16 KiB per cascade) and the atlas slots the
// stack rewrote are uploaded.
#pragma once

#include <span>
#include <vector>

#include "gi/cpu_tracer.h"
#include "gi/gpu_stack_scene.h"
#include "gi/ray_batch.h"
#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "gpu/compute_pipeline.h"
#include "gpu/context.h"
#include "streaming/cascade_stack.h"

namespace sdfstream {

class GpuStackTracer {
 public:
  // cellCorners: as GpuStackScene's (the traces are the same either way, bit for bit).
  GpuStackTracer(gpu::Context& context, const CascadeStack& stack, bool cellCorners = true);

  // Uploads the stack's page tables, params and the given dirty atlas slots (from
  // CascadeStack::takeDirtySlots). Returns the bytes uploaded.
  std::size_t sync(const CascadeStack& stack, std::span<const std::uint32_t> dirtySlots) {
    return scene_.sync(stack, dirtySlots);
  }
  const GpuStackScene& scene() const { return scene_; }

  // Traces rays given in cascade-0 voxels (CascadeStackImage::toStack); blocks for the results.
  // `dispatches` > 1 traces the same rays that many times back to back in one submission (the
  // same hits each time; lastTimings() lists every dispatch): a benchmark's way to time the pass
  // with the GPU busy, so that its clocks have left their idle state (1..60).
  std::vector<gpu_shared::TraceHit> trace(std::span<const gpu_shared::TraceRay> rays,
                                          const TraceSettings& settings,
                                          std::uint32_t dispatches = 1);
  const std::vector<gpu::PassTiming>& lastTimings() const { return timings_; }
  double lastMilliseconds(const std::string& pass) const;

 private:
  gpu::Context& context_;
  RayBatch batch_;
  gpu::ComputePipelinePair pipeline_;  // specialized on the atlas the scene traces
  GpuStackScene scene_;
  std::vector<gpu::PassTiming> timings_;
};

}  // namespace sdfstream
