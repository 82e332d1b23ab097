// The ray and hit buffers of a trace pass, grown on demand and reused across calls, shared by
// the single-cascade and the stack tracers.
#pragma once

#include <span>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/context.h"
#include "shaders/shared/sdf_layout.h"

namespace sdfstream {

class RayBatch {
 public:
  explicit RayBatch(gpu::Context& context) : context_(context) {}
  // Makes room for rays.size() rays and hits and copies the rays in (host-visible buffer).
  void stage(std::span<const gpu_shared::TraceRay> rays);
  // The hits of the last staged batch, after the pass has completed.
  std::vector<gpu_shared::TraceHit> readHits() const;
  gpu::Buffer& rays() { return rays_; }
  gpu::Buffer& hits() { return hits_; }
  std::uint32_t count() const { return count_; }

 private:
  gpu::Context& context_;
  gpu::Buffer rays_, hits_;
  std::uint32_t count_ = 0;
};

}  // namespace sdfstream
