#include "tools/view_renderer.h"

#include <chrono>

namespace sdfstream {

ViewRenderer::ViewRenderer(const World& world, gpu::Context* context, TraceSettings settings)
    : world_(world), context_(context), settings_(settings) {
  if (context_) gpu_ = std::make_unique<GpuTracer>(*context_);
}

ViewResult ViewRenderer::render(const Camera& camera, int width, int height) {
  glm::ivec3 origin = cascadeOriginAround(world_, camera.target);
  if (!cascade_ || cascade_->originBrick != origin) {
    cascade_ = buildCascade(world_, origin);
    if (gpu_) gpu_->setCascade(*cascade_);
  }
  ViewResult r;
  r.residentBricks = cascade_->residentBricks;
  r.cascadeBytes = cascade_->gpuBytes();
  auto rays = primaryRays(camera, width, height, *cascade_);
  r.rays = rays.size();
  std::vector<gpu_shared::TraceHit> hits;
  if (gpu_) {
    hits = gpu_->trace(rays, settings_);
    r.traceMilliseconds = gpu_->lastTraceMilliseconds();
    r.passes = gpu_->lastTimings();
  } else {
    auto start = std::chrono::steady_clock::now();
    hits = traceRaysCpu(*cascade_, rays, settings_);
    r.traceMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    r.passes.push_back({"trace (cpu)", r.traceMilliseconds});
  }
  for (const auto& h : hits) r.hits += (h.flags & gpu_shared::kHitFlagHit) ? 1 : 0;
  r.image = shadeHits(hits, width, height);
  return r;
}

Camera defaultCamera(const World& world) {
  return frameBounds(world.worldMin(), world.worldMax(), glm::dvec3(0.55, 0.45, 1.0));
}

}  // namespace sdfstream
