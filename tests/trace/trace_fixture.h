// A real closed mesh (Debian glmark2-data's Stanford bunny, 69,666 triangles) on a box,
// imported to bricks and loaded into one cascade: the shared set-up of the trace tests.
#pragma once

#include <memory>
#include <random>
#include <vector>

#include "gi/cpu_tracer.h"
#include "streaming/cascade.h"
#include "world/mesh_to_sdf.h"
#include "world/obj_import.h"
#include "world/triangle_scene.h"

namespace sdfstream::test {

struct TraceScene {
  TriangleScene triangles;
  World world;
  CascadeImage cascade;
};

inline TraceScene makeBunnyScene() {
  TraceScene s;
  s.triangles = loadObj("/usr/share/glmark2/models/bunny.obj");
  ImportLimits limits;
  s.world = meshToWorld(s.triangles, defaultVoxelSize(s.triangles), limits);
  s.cascade = buildCascade(s.world, cascadeOriginForWorld(s.world));
  return s;
}

// Rays from random points on a sphere around the scene towards random points in its bounds,
// in world space (origin, unit direction).
struct WorldRay {
  glm::dvec3 origin;
  glm::dvec3 dir;
};
inline std::vector<WorldRay> randomRaysAround(const TriangleScene& scene, int count,
                                              unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  glm::dvec3 lo(scene.boundsMin()), hi(scene.boundsMax());
  glm::dvec3 center = 0.5 * (lo + hi);
  double radius = 0.5 * glm::length(hi - lo) * 1.3;
  std::vector<WorldRay> rays;
  for (int i = 0; i < count; ++i) {
    double z = 2.0 * u(rng) - 1.0, phi = 6.283185307179586 * u(rng);
    double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    glm::dvec3 o = center + radius * glm::dvec3(r * std::cos(phi), r * std::sin(phi), z);
    glm::dvec3 target = lo + (hi - lo) * glm::dvec3(u(rng), u(rng), u(rng));
    rays.push_back({o, glm::normalize(target - o)});
  }
  return rays;
}

inline std::vector<gpu_shared::TraceRay> toCascadeRays(const std::vector<WorldRay>& rays,
                                                       const CascadeImage& c) {
  std::vector<gpu_shared::TraceRay> out(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) {
    out[i].originTMin = glm::vec4(c.toCascade(rays[i].origin), 0.0f);
    out[i].dirTMax = glm::vec4(glm::vec3(rays[i].dir), 1e30f);
  }
  return out;
}

}  // namespace sdfstream::test
