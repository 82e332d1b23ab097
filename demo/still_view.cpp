#include "demo/still_view.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "demo/gi_shading.h"
#include "gi/scene_lights.h"

namespace sdfstream {

Camera defaultStillCamera(const glm::dvec3& boundsMin, const glm::dvec3& boundsMax, double aspect) {
  // Across the longer horizontal axis, so it spans the picture's width, from 67 degrees up: a
  // yawed view of a box leaves its corners' triangles empty (Sponza at 16:9: 61% of the pixels
  // hit 6 degrees off the axis, 65% on it, 48% from 45 degrees).
  const glm::dvec3 size = boundsMax - boundsMin;
  const glm::dvec3 from = size.x >= size.z ? glm::dvec3(0.0, 2.4, 1.0) : glm::dvec3(1.0, 2.4, 0.0);
  return frameBoxTightly(boundsMin, boundsMax, from, 50.0, aspect);
}

Camera interiorStillCamera(const glm::dvec3& boundsMin, const glm::dvec3& boundsMax, int axis,
                           int sign, bool outside) {
  const glm::dvec3 size = boundsMax - boundsMin;
  const double from = sign > 0 ? boundsMin[axis] : boundsMax[axis];
  Camera c;
  c.position = (boundsMin + boundsMax) / 2.0;
  c.position[axis] = from + sign * (outside ? -0.6 : 1.0 / 12.0) * size[axis];
  c.position.y = boundsMin.y + size.y * (outside ? 0.5 : 1.0 / 3.0);
  c.target = c.position;
  c.target[axis] = sign > 0 ? boundsMax[axis] : boundsMin[axis];
  c.target.y = boundsMin.y + size.y * (outside ? 0.4 : 0.25);
  c.fovYDegrees = outside ? 50.0 : 70.0;
  return c;
}

namespace {

// The view's primary hits on the CPU at a small size, on the stack as it stands.
struct TracedView {
  std::vector<gpu_shared::TraceRay> rays;  // stack space: cascade-0 voxels
  std::vector<gpu_shared::ShadedHit> hits;
  glm::dvec3 stackMinWorld{0.0};  // the stack's frame, to bring hits back to world metres
  double voxelSize0 = 0.0;
};

TracedView traceSmall(StreamedGi& world, const Camera& camera, int width, int height) {
  const CascadeStackImage img = world.stack().stackImage();
  const RenderOptions& r = world.render();
  TracedView v;
  v.stackMinWorld = img.cascade0MinWorld;
  v.voxelSize0 = img.voxelSize0;
  v.rays = cameraRays(camera, width, height, img);
  v.hits = shadePrimaryCpu(img, v.rays, toGpu(r.lights.lights, img), toGpu(r.lights.sky),
                           r.renderer.shading, {});
  return v;
}

}  // namespace

Camera defaultStillCamera(StreamedGi& world, double aspect) {
  const PackManifest& m = world.store().manifest();
  const Camera overview = defaultStillCamera(m.boundsMin, m.boundsMax, aspect);
  world.settle(stillViewCentre(overview, m.boundsMin, m.boundsMax),
               glm::normalize(overview.target - overview.position));
  const TracedView over = traceSmall(world, overview, 96, 54);
  const double roofLine = m.boundsMin.y + 0.8 * (m.boundsMax.y - m.boundsMin.y);
  std::size_t hit = 0, roof = 0;
  for (std::size_t i = 0; i < over.hits.size(); ++i) {
    if (!(over.hits[i].flags & gpu_shared::kHitFlagHit)) continue;
    ++hit;
    const float t = over.hits[i].normalT.w;
    const glm::vec3 p = glm::vec3(over.rays[i].originTMin) + glm::vec3(over.rays[i].dirTMax) * t;
    const double y = over.stackMinWorld.y + double(p.y) * over.voxelSize0;
    roof += over.hits[i].normalT.y > 0.7f && y > roofLine;
  }
  if (hit == 0 || 2 * roof <= hit) return overview;
  // Into it: of eight views along the horizontal axes (from inside each end, and from outside
  // it looking in), the one that sees deepest into the bounds (summed distance from where each
  // ray enters the bounds to its hit; a miss counts nothing): down a nave rather than into a
  // wall, into a box through its open side rather than at a closed one.
  Camera best = overview;
  double bestScore = -1.0;
  for (int axis : {0, 2})
    for (int sign : {1, -1})
      for (bool outside : {false, true}) {
        const Camera c = interiorStillCamera(m.boundsMin, m.boundsMax, axis, sign, outside);
        world.settle(stillViewCentre(c, m.boundsMin, m.boundsMax),
                     glm::normalize(c.target - c.position));
        const TracedView v = traceSmall(world, c, 48, 27);
        double score = 0.0;
        for (std::size_t i = 0; i < v.hits.size(); ++i) {
          if (!(v.hits[i].flags & gpu_shared::kHitFlagHit)) continue;
          const glm::dvec3 d = glm::dvec3(glm::vec3(v.rays[i].dirTMax));
          double enter = 0.0;  // slab test: where the ray enters the bounds, metres
          for (int k = 0; k < 3; ++k)
            if (std::abs(d[k]) > 1e-12) {
              const double t0 = (m.boundsMin[k] - c.position[k]) / d[k];
              const double t1 = (m.boundsMax[k] - c.position[k]) / d[k];
              enter = std::max(enter, std::min(t0, t1));
            }
          score += std::max(0.0, double(v.hits[i].normalT.w) * v.voxelSize0 - enter);
        }
        // A view from outside frames the whole opening: preferred unless an inside view sees
        // half as deep again (Sponza's ends are walls: from outside they score about nothing).
        if (outside) score *= 1.5;
        if (score > bestScore) {
          bestScore = score;
          best = c;
        }
      }
  return best;
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
