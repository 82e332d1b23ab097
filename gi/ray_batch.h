// The ray and hit buffers of a trace pass, grown on demand and reused across calls, shared by
// the single-cascade and the stack tracers. The pass binds device-local rays and hits
// (gpu/staged_buffer.h says why); record recordUpload() before it and recordReadback() after.
#pragma once

#include <span>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "gpu/context.h"
#include "gpu/staged_buffer.h"
#include "shaders/shared/sdf_layout.h"

namespace sdfstream {

class RayBatch {
 public:
  explicit RayBatch(gpu::Context& context)
      : rays_(context, gpu::StagedBuffer::ToDevice), hits_(context, gpu::StagedBuffer::ToHost) {}
  // Makes room for rays.size() rays and hits and copies the rays to the host-visible staging.
  void stage(std::span<const gpu_shared::TraceRay> rays);
  void recordUpload(gpu::CommandBatch& batch);    // staged rays -> rays()
  void recordReadback(gpu::CommandBatch& batch);  // hits() -> host, for readHits()
  // The hits of the last staged batch, after the pass has completed.
  std::vector<gpu_shared::TraceHit> readHits() const;
  gpu::Buffer& rays() { return rays_.device(); }
  gpu::Buffer& hits() { return hits_.device(); }
  std::uint32_t count() const { return count_; }

 private:
  gpu::StagedBuffer rays_, hits_;
  std::uint32_t count_ = 0;
};

}  // namespace sdfstream
