// The small scene of the demo_gi tests, built with the layout importer: a white floor (top at
// y = 0, 4 x 4 m), a red wall on its -x side and a white pillar, lit by a sun from +x (travelling
// towards the red wall), seen from the front, above. Metres.
#pragma once

#include <cmath>
#include <fstream>
#include <memory>
#include <vector>

#include "demo/gi_shading.h"
#include "tests/support/test_data.h"
#include "world/mesh_to_sdf.h"
#include "world/scene_layout.h"

namespace sdfstream::test {

// The sun comes from +x and slightly from +z, so the pillar's shadow falls towards -x and the
// red wall's inner face (+x) is lit.
inline TriangleScene demoGiTriangles() {
  const auto dir = scratchDir("demo-gi");
  std::ofstream(dir / "layout.json") << R"({"boxes": [
    {"min": [-2.0, -0.2, -2.0], "max": [2.0, 0.0, 2.0], "albedo": [0.8, 0.8, 0.8]},
    {"min": [-2.0, 0.0, -2.0], "max": [-1.8, 2.0, 2.0], "albedo": [0.85, 0.08, 0.06]},
    {"min": [0.8, 0.0, -0.25], "max": [1.2, 1.4, 0.25], "albedo": [0.8, 0.8, 0.8]}]})";
  return loadLayout(dir / "layout.json");
}

inline World demoGiWorld() { return meshToWorld(demoGiTriangles(), 0.0, ImportLimits{}); }

inline const glm::vec3 kDemoGiSunTravel(-0.5f, -1.0f, -0.1f);

// Sun and a black sky: every bit of light in a shadow has bounced at least once.
inline SceneLights demoGiLights() {
  return defaultSceneLights(kDemoGiSunTravel, 3.0f, glm::vec3(0.0f), glm::vec3(0.0f));
}

inline Camera demoGiCamera() {
  Camera c;
  c.position = glm::dvec3(0.3, 3.2, 3.6);
  c.target = glm::dvec3(0.0, 0.0, 0.0);
  c.fovYDegrees = 55.0;
  return c;
}

// A GI renderer with the demo tests' probe settings (64 rays a probe, probes two bricks apart:
// 9³ probes 0.5 m apart, enough for the 4 m room), run for `frames` GI frames on `image` with
// `camera` fixed, so its probes have converged that far.
inline std::unique_ptr<GiRenderer> demoGiRenderer(gpu::Context& ctx, const CascadeStackImage& image,
                                                  const SceneLights& lights, const Camera& camera,
                                                  int frames) {
  GiRendererOptions options;
  options.settings.probes.raysPerProbe = 64;
  options.settings.probes.spacingBricks = 2;
  auto gi = std::make_unique<GiRenderer>(ctx, options, 1);
  probe::ProbeFrameInputs inputs;
  inputs.cameraWorld = camera.position;
  inputs.viewDirection = glm::vec3(glm::normalize(camera.target - camera.position));
  for (int f = 0; f < frames; ++f) gi->update(image, lights, inputs, std::uint64_t(f));
  return gi;
}

// World position of pixel i's primary hit (view traced in `image`'s stack space).
inline glm::dvec3 hitWorld(const ShadedView& view, const CascadeStackImage& image, std::size_t i) {
  const glm::vec3 p = glm::vec3(view.rays[i].originTMin) +
                      glm::vec3(view.rays[i].dirTMax) * view.shaded[i].normalT.w;
  return image.cascade0MinWorld + glm::dvec3(p) * image.voxelSize0;
}

// Whether pixel i's primary hit is the static floor's top (normal up, y = 0) inside the world
// rectangle [x0, x1] x [z0, z1].
struct FloorRegion {
  float x0, x1, z0, z1;
};
inline bool onFloor(const ShadedView& view, const CascadeStackImage& image, std::size_t i,
                    FloorRegion r) {
  const gpu_shared::ShadedHit& h = view.shaded[i];
  if (!(h.flags & gpu_shared::kHitFlagHit) || (h.flags & gpu_shared::kShadeFlagObject) ||
      h.normalT.y < 0.9f)
    return false;
  const glm::dvec3 w = hitWorld(view, image, i);
  return std::abs(w.y) <= 0.05 && w.x >= r.x0 && w.x <= r.x1 && w.z >= r.z0 && w.z <= r.z1;
}

// Mean linear radiance of the floor pixels of `view` inside r.
inline glm::dvec3 floorMean(const ShadedView& view, const CascadeStackImage& image,
                            const std::vector<glm::vec3>& radiance, FloorRegion r, int* count) {
  glm::dvec3 sum(0.0);
  int n = 0;
  for (std::size_t i = 0; i < view.shaded.size(); ++i) {
    if (!onFloor(view, image, i, r)) continue;
    sum += glm::dvec3(radiance[i]);
    ++n;
  }
  *count = n;
  return n ? sum / double(n) : sum;
}

inline double lum(glm::dvec3 c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

}  // namespace sdfstream::test
