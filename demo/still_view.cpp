#include "demo/still_view.h"

#include <algorithm>

namespace sdfstream {

Camera defaultStillCamera(const glm::dvec3& boundsMin, const glm::dvec3& boundsMax, double aspect) {
  // Across the longer horizontal axis, so it spans the picture's width, from 67 degrees up: a
  // yawed view of a box leaves its corners' triangles empty (Sponza at 16:9: 61% of the pixels
  // hit 6 degrees off the axis, 65% on it, 48% from 45 degrees).
  const glm::dvec3 size = boundsMax - boundsMin;
  const glm::dvec3 from = size.x >= size.z ? glm::dvec3(0.0, 2.4, 1.0) : glm::dvec3(1.0, 2.4, 0.0);
  return frameBoxTightly(boundsMin, boundsMax, from, 50.0, aspect);
}

glm::dvec3 stillViewCentre(const Camera& camera, const glm::dvec3& boundsMin,
                           const glm::dvec3& boundsMax) {
  const bool inside = glm::all(glm::greaterThanEqual(camera.position, boundsMin)) &&
                      glm::all(glm::lessThanEqual(camera.position, boundsMax));
  return inside ? camera.position : camera.target;
}

ViewResult renderStill(StreamedGi& world, const Camera& camera, int width, int height,
                       int giFrames) {
  const PackManifest& manifest = world.store().manifest();
  const glm::dvec3 direction = glm::normalize(camera.target - camera.position);
  const StreamFrameStats streamed =
      world.settle(stillViewCentre(camera, manifest.boundsMin, manifest.boundsMax), direction);
  ViewResult r;
  for (const CascadeFrameStats& c : streamed.cascades) r.residentBricks += c.residentBricks;
  r.cascadeBytes = world.stack().atlasBytes();

  GiRenderer* gpu = world.renderer();
  if (!gpu) {
    r.frame = world.renderFrame(camera, width, height, &r.shadeMilliseconds);
    r.rays = std::size_t(width) * std::size_t(height);
  } else {
    int frame = 0;
    auto step = [&] {
      world.withinDeviceMemory(frame, [&] { world.giUpdate(camera); });
      ++frame;
      const GiFrameTimes& t = gpu->lastTimes();
      r.lightMilliseconds += t.gi.lightMilliseconds;
      r.objectMilliseconds += t.gi.objectMilliseconds;
      if (gpu->giEnabled()) {
        r.probeMilliseconds.push_back(t.gi.probeMilliseconds);
        r.probePasses = t.probePasses;
      }
    };
    step();  // uploads the stack, which the shading pass reads
    ShadedView view;
    world.withinDeviceMemory(frame, [&] {
      view = gpu->shade(camera, width, height, world.stack().stackImage(), world.render().lights);
    });
    r.rays = view.rays.size();
    if (gpu->giEnabled()) {
      // A fixed subset of this view's receivers tracks convergence frame by frame.
      std::vector<gpu_shared::ProbeQuery> subset;
      for (std::size_t i = 0; i < view.queries.size(); i += 61) subset.push_back(view.queries[i]);
      r.convergence.push_back(gpu->meanIrradiance(subset));
      while (frame < giFrames) {
        step();
        r.convergence.push_back(gpu->meanIrradiance(subset));
      }
      r.framesToConverge = framesToConverge(r.convergence);
    }
    r.shadeMilliseconds = gpu->lastTimes().shadeMilliseconds;
    r.rasterMilliseconds = gpu->lastTimes().rasterMilliseconds;
    world.withinDeviceMemory(frame, [&] { r.frame = gpu->finish(view); });
    r.sampleMilliseconds = gpu->lastTimes().sampleMilliseconds;
  }
  r.hits = r.frame.hits;
  r.objectHits = r.frame.objectHits;
  const float ev = world.render().exposureStops;
  r.image = toneMap(r.frame.final(), width, height, ev, &r.nonFinite);
  r.directImage = toneMap(r.frame.direct, width, height, ev);
  r.indirectImage = toneMap(r.frame.indirect, width, height, ev);
  return r;
}

}  // namespace sdfstream
