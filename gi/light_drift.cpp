#include "gi/light_drift.h"

#include <algorithm>
#include <cmath>

namespace sdfstream {
namespace {

bool closeRadiance(glm::vec3 a, glm::vec3 b, float limit) {
  for (int i = 0; i < 3; ++i) {
    const float top = std::max(std::abs(a[i]), std::abs(b[i]));
    if (std::abs(a[i] - b[i]) > limit * top) return false;
  }
  return true;
}

bool sameExceptRadianceAndDirection(const SceneLight& a, const SceneLight& b) {
  return a.type == b.type && a.position == b.position && a.range == b.range &&
         a.innerConeDegrees == b.innerConeDegrees && a.outerConeDegrees == b.outerConeDegrees &&
         a.shadowSharpness == b.shadowSharpness && a.castsShadows == b.castsShadows;
}

}  // namespace

bool isLightDrift(const SceneLights& before, const SceneLights& now,
                  const LightDriftLimits& limits) {
  if (!(limits.degrees > 0.0f) || before.lights.size() != now.lights.size()) return false;
  const float cosLimit = std::cos(glm::radians(limits.degrees));
  for (std::size_t i = 0; i < now.lights.size(); ++i) {
    const SceneLight& a = before.lights[i];
    const SceneLight& b = now.lights[i];
    if (!sameExceptRadianceAndDirection(a, b)) return false;
    if (!closeRadiance(a.color * a.intensity, b.color * b.intensity, limits.intensity))
      return false;
    if (a.direction == b.direction) continue;
    // A spot that turns sweeps its cone over new surfaces: not a drift. A sun that turns a
    // little changes every surface's cosine a little.
    if (a.type != SceneLight::Type::Sun) return false;
    const float la = glm::length(a.direction), lb = glm::length(b.direction);
    if (!(la > 0.0f) || !(lb > 0.0f)) return false;
    if (glm::dot(a.direction, b.direction) / (la * lb) < cosLimit) return false;
  }
  return closeRadiance(before.sky.zenith, now.sky.zenith, limits.intensity) &&
         closeRadiance(before.sky.horizon, now.sky.horizon, limits.intensity);
}

}  // namespace sdfstream
