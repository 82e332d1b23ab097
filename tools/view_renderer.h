// Renders views of a World: places the cascade around the camera's target, traces primary
// rays on the GPU (or with the CPU reference when no context is given) and shades a preview.
// Used by `sdfstream render` and `sdfstream demo`.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "demo/frame_image.h"
#include "gi/camera.h"
#include "gi/cpu_tracer.h"
#include "gi/gpu_tracer.h"
#include "world/world.h"

namespace sdfstream {

struct ViewResult {
  Image8 image;
  std::size_t rays = 0;
  std::size_t hits = 0;
  double traceMilliseconds = 0.0;  // GPU timestamp of the trace pass, or CPU wall time
  std::vector<gpu::PassTiming> passes;
  std::uint32_t residentBricks = 0;
  std::size_t cascadeBytes = 0;
};

class ViewRenderer {
 public:
  // context == nullptr: trace with the CPU reference.
  ViewRenderer(const World& world, gpu::Context* context, TraceSettings settings = {});
  ViewResult render(const Camera& camera, int width, int height);

 private:
  const World& world_;
  gpu::Context* context_;
  TraceSettings settings_;
  std::unique_ptr<GpuTracer> gpu_;
  std::optional<CascadeImage> cascade_;
};

// The default view: the whole world from the front-right, slightly above.
Camera defaultCamera(const World& world);

}  // namespace sdfstream
