// The lights and sky of a scene in world units (metres, linear RGB): what the demo, the GI and
// the path-traced reference are given. Header-only description, no GPU form: gi/scene_lights.h
// turns it into the shared GPU structs for one cascade stack, so the reference (which judges the
// GI) can read a scene's lights without depending on the GI. Semantics of each field are those
// of shaders/shared/light_layout.h.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace sdfstream {

struct SceneLight {
  enum class Type { Sun, Point, Spot };
  Type type = Type::Sun;
  glm::dvec3 position{0.0};        // world metres (point, spot)
  glm::vec3 direction{0, -1, 0};   // sun: the way light travels; spot: the way it points
  glm::vec3 color{1.0f};           // linear RGB
  float intensity = 1.0f;          // sun: irradiance; point/spot: intensity (W/sr scale)
  float innerConeDegrees = 20.0f;  // spot: full intensity inside this half-angle
  float outerConeDegrees = 30.0f;  // spot: zero outside this half-angle
  float range = 0.0f;              // metres, 0 = unbounded (1/d² only)
  float shadowSharpness = 16.0f;   // soft-shadow k (larger = harder), 0 = hard shadows
  bool castsShadows = true;
};

// `light` moved by an affine transform: position = m · p, direction = m · d renormalised (a
// degenerate transform keeps the light's own direction rather than NaN). Cone angles, range and
// intensity are kept: a scaled placement does not rescale the light.
inline SceneLight transformLight(SceneLight light, const glm::dmat4& m) {
  light.position = glm::dvec3(m * glm::dvec4(light.position, 1.0));
  const glm::dvec3 d(m * glm::dvec4(glm::dvec3(light.direction), 0.0));
  const double len = glm::length(d);
  if (len > 0.0 && len < 1e300) light.direction = glm::vec3(d / len);
  return light;
}

struct SceneSky {
  glm::vec3 zenith{0.0f};   // radiance straight up (linear RGB)
  glm::vec3 horizon{0.0f};  // radiance at/below the horizon
};

struct SceneLights {
  std::vector<SceneLight> lights;  // at most gpu_shared::kMaxLights (gi/scene_lights.h checks)
  SceneSky sky;
  // Bumped by whoever edits the lights; the light cache relights everything when it changes.
  std::uint64_t version = 0;
};

}  // namespace sdfstream
