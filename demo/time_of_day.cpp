#include "demo/time_of_day.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sdfstream {
namespace {

constexpr double kDegrees = std::numbers::pi / 180.0;
constexpr glm::dvec3 kOpticalDepth(0.09, 0.15, 0.28);

}  // namespace

double relativeAirMass(double elevationDegrees) {
  const double e = std::max(0.0, elevationDegrees);
  return 1.0 / (std::sin(e * kDegrees) + 0.50572 * std::pow(e + 6.07995, -1.6364));
}

double sunElevationDegrees(const glm::vec3& direction) {
  const glm::dvec3 d = glm::normalize(glm::dvec3(direction));
  return std::asin(std::clamp(-d.y, -1.0, 1.0)) / kDegrees;
}

SceneLights daylightAt(const SceneLights& given, double elevationDegrees) {
  SceneLights out = given;
  bool skyDone = false;
  for (SceneLight& l : out.lights) {
    if (l.type != SceneLight::Type::Sun) continue;
    const double e0 = sunElevationDegrees(l.direction);
    glm::dvec2 horizontal(l.direction.x, l.direction.z);
    horizontal = glm::length(horizontal) > 1e-6 ? glm::normalize(horizontal) : glm::dvec2(1, 0);
    const double c = std::cos(elevationDegrees * kDegrees),
                 s = std::sin(elevationDegrees * kDegrees);
    l.direction = glm::vec3(glm::dvec3(horizontal.x * c, -s, horizontal.y * c));
    const double dm = relativeAirMass(elevationDegrees) - relativeAirMass(e0);
    const glm::vec3 reddening(glm::exp(-kOpticalDepth * dm));
    l.color *= reddening;
    if (!skyDone) {
      skyDone = true;
      const double ratio = std::max(0.0, s) / std::max(1e-3, std::sin(e0 * kDegrees));
      const float scale = float(std::max(0.05, std::pow(ratio, 0.7)));
      // The horizon takes on the setting sun's hue, normalised to keep its brightness.
      const glm::vec3 hue =
          reddening / std::max(1e-6f, (reddening.r + reddening.g + reddening.b) / 3);
      const float tint = std::clamp(1.0f - scale, 0.0f, 1.0f) * 0.6f;
      out.sky.zenith = given.sky.zenith * std::min(1.0f, scale);
      out.sky.horizon =
          given.sky.horizon * std::min(1.0f, scale) * glm::mix(glm::vec3(1.0f), hue, tint);
    }
  }
  return out;
}

}  // namespace sdfstream
