#include "demo/view_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/stopwatch.h"

namespace sdfstream {

ViewRenderer::ViewRenderer(const World& world, gpu::Context* context, const RenderOptions& options,
                           TraceSettings trace)
    : world_(world), context_(context), options_(options) {
  options_.renderer.shading.trace = trace;
  options_.renderer.gi = options_.gi && context_;
  if (context_) gpu_ = std::make_unique<GiRenderer>(*context_, options_.renderer, 1u);
}

ViewRenderer::~ViewRenderer() = default;

void ViewRenderer::setObjects(DemoObjects* objects, int giFrames) {
  objects_ = objects;
  objectFrame_ = 0;
  objectTarget_ = objects ? framesOnWindow_ + giFrames : 0;
  if (gpu_)
    gpu_->setObjects(objects ? &objects->library : nullptr,
                     objects ? &objects->instances : nullptr);
}

ViewResult ViewRenderer::render(const Camera& camera, int width, int height) {
  const glm::ivec3 origin = cascadeOriginAround(world_, camera.target);
  if (!cascade_ || cascade_->originBrick != origin) {
    cascade_ = buildCascade(world_, origin);
    stack_ = std::make_unique<CascadeStackImage>(stackImageOf(*cascade_));
    framesOnWindow_ = 0;
  }
  ViewResult r;
  r.residentBricks = cascade_->residentBricks;
  r.cascadeBytes = cascade_->gpuBytes();
  const SceneLights& lights = options_.lights;

  if (!gpu_) {
    const auto rays = cameraRays(camera, width, height, *stack_);
    const auto gpuLights = toGpu(lights.lights, *stack_);
    auto start = std::chrono::steady_clock::now();
    if (options_.renderer.shading.direct == gpu_shared::kShadeDirectCache && framesOnWindow_ == 0) {
      cpuLight_.update(*stack_, gpuLights, toGpu(lights.sky),
                       lightDirtyPages(nullptr, *stack_, true), stack_->voxelSize0);
      ++framesOnWindow_;
    }
    const auto shaded = shadePrimaryCpu(*stack_, rays, gpuLights, toGpu(lights.sky),
                                        options_.renderer.shading, cpuLight_.radiance());
    r.shadeMilliseconds = millisecondsSince(start);
    r.rays = rays.size();
    r.frame = composeFrame(shaded, width, height, {}, {});
  } else {
    probe::ProbeFrameInputs inputs;
    inputs.cameraWorld = camera.position;
    inputs.viewDirection = glm::vec3(glm::normalize(camera.target - camera.position));
    auto step = [&] {
      if (objects_) objects_->apply(objectFrame_++ / 30.0);
      gpu_->update(*stack_, lights, inputs, frame_++);
      ++framesOnWindow_;
      const GiFrameTimes& t = gpu_->lastTimes();
      r.lightMilliseconds += t.gi.lightMilliseconds;
      r.objectMilliseconds += t.gi.objectMilliseconds;
      r.objectRays = t.gi.probes.objectRays;
      r.objectRayHits = t.gi.probes.objectHits;
      if (gpu_->giEnabled()) {
        r.probeMilliseconds.push_back(t.gi.probeMilliseconds);
        r.probePasses = t.probePasses;
      }
    };
    // The first frame uploads the stack, which the shading pass reads.
    if (framesOnWindow_ == 0) step();
    ShadedView view = gpu_->shade(camera, width, height, *stack_, lights);
    r.rays = view.rays.size();
    bool moved = false;  // objects moved after the view was shaded
    if (gpu_->giEnabled()) {
      // A fixed subset of this view's receivers tracks convergence frame by frame.
      std::vector<gpu_shared::ProbeQuery> subset;
      for (std::size_t i = 0; i < view.queries.size(); i += 61) subset.push_back(view.queries[i]);
      if (!r.probeMilliseconds.empty()) r.convergence.push_back(gpu_->meanIrradiance(subset));
      while (framesOnWindow_ < std::max(options_.giFrames, objectTarget_)) {
        step();
        moved = moved || objects_;
        r.convergence.push_back(gpu_->meanIrradiance(subset));
      }
      r.framesToConverge = framesToConverge(r.convergence);
    } else if (objects_) {
      while (framesOnWindow_ < objectTarget_) step(), moved = true;
    }
    // Shading does not depend on the probes, but it does on where the objects are.
    if (moved) view = gpu_->shade(camera, width, height, *stack_, lights);
    r.shadeMilliseconds = gpu_->lastTimes().shadeMilliseconds;
    r.frame = gpu_->finish(view);
    r.sampleMilliseconds = gpu_->lastTimes().sampleMilliseconds;
  }
  r.hits = r.frame.hits;
  r.objectHits = r.frame.objectHits;
  const float ev = options_.exposureStops;
  r.image = toneMap(r.frame.final(), width, height, ev, &r.nonFinite);
  r.directImage = toneMap(r.frame.direct, width, height, ev);
  r.indirectImage = toneMap(r.frame.indirect, width, height, ev);
  return r;
}

Camera defaultCamera(const World& world) {
  return frameBounds(world.worldMin(), world.worldMax(), glm::dvec3(0.55, 0.45, 1.0));
}

int framesToConverge(const std::vector<glm::vec3>& series, float tolerance) {
  if (series.empty()) return 0;
  const float last = luminance(series.back());
  int first = int(series.size()) - 1;
  for (int i = int(series.size()) - 1; i >= 0; --i) {
    if (std::abs(luminance(series[i]) - last) > tolerance * std::max(last, 1e-6f)) break;
    first = i;
  }
  return first + 1;  // frames run, counting from 1
}

}  // namespace sdfstream
