// demo/time_of_day.h: the sun sinks with its azimuth kept, reddens and dims monotonically as the
// air mass grows, nothing changes at the elevation it was given at, and the sky dims with it.
#include <cmath>

#include <gtest/gtest.h>

#include "demo/time_of_day.h"

namespace sdfstream {
namespace {

SceneLights noon() {
  SceneLights l;
  SceneLight sun;
  sun.direction = glm::normalize(glm::vec3(0.45f, -0.7f, -0.55f));
  sun.color = glm::vec3(1.0f, 0.95f, 0.9f);
  sun.intensity = 3.0f;
  l.lights.push_back(sun);
  SceneLight lamp;
  lamp.type = SceneLight::Type::Point;
  lamp.color = glm::vec3(1.0f, 0.5f, 0.2f);
  l.lights.push_back(lamp);
  l.sky = {{0.06f, 0.11f, 0.25f}, {0.2f, 0.22f, 0.26f}};
  l.version = 7;
  return l;
}

TEST(TimeOfDay, AirMassIsOneOverheadAndAboutThirtyEightAtTheHorizon) {
  EXPECT_NEAR(relativeAirMass(90.0), 1.0, 1e-3);
  EXPECT_NEAR(relativeAirMass(30.0), 1.0 / std::sin(30.0 * M_PI / 180.0), 0.01);
  EXPECT_NEAR(relativeAirMass(0.0), 38.0, 0.2);
  EXPECT_EQ(relativeAirMass(-5.0), relativeAirMass(0.0));
}

TEST(TimeOfDay, AtItsOwnElevationNothingChanges) {
  const SceneLights given = noon();
  const double e0 = sunElevationDegrees(given.lights[0].direction);
  EXPECT_NEAR(e0, std::asin(0.7 / glm::length(glm::vec3(0.45f, -0.7f, -0.55f))) * 180 / M_PI, 1e-4);
  const SceneLights same = daylightAt(given, e0);
  EXPECT_NEAR(glm::length(same.lights[0].direction - given.lights[0].direction), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::length(same.lights[0].color - given.lights[0].color), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::length(same.sky.zenith - given.sky.zenith), 0.0f, 1e-5f);
  EXPECT_EQ(same.version, given.version);  // the caller bumps it
}

TEST(TimeOfDay, SettingSunReddensDimsAndKeepsItsAzimuth) {
  const SceneLights given = noon();
  glm::vec3 previous = given.lights[0].color;
  float previousRatio = previous.r / previous.b;
  float previousZenith = glm::length(given.sky.zenith);
  for (double e : {30.0, 20.0, 10.0, 5.0, 2.0}) {
    const SceneLights at = daylightAt(given, e);
    const SceneLight& sun = at.lights[0];
    EXPECT_NEAR(sunElevationDegrees(sun.direction), e, 1e-3);
    // Same azimuth: the horizontal part points the same way.
    const glm::vec2 h0 =
        glm::normalize(glm::vec2(given.lights[0].direction.x, given.lights[0].direction.z));
    const glm::vec2 h = glm::normalize(glm::vec2(sun.direction.x, sun.direction.z));
    EXPECT_NEAR(glm::dot(h0, h), 1.0f, 1e-5f);
    EXPECT_LT(sun.color.g, previous.g) << e;
    EXPECT_GT(sun.color.r / sun.color.b, previousRatio) << e;
    EXPECT_LT(glm::length(at.sky.zenith), previousZenith) << e;
    EXPECT_EQ(at.lights[1].color, given.lights[1].color);  // a lamp is not the sun
    previous = sun.color;
    previousRatio = sun.color.r / sun.color.b;
    previousZenith = glm::length(at.sky.zenith);
  }
  // Near the horizon the sun is a deep orange: blue under a tenth of red.
  const glm::vec3 low = daylightAt(given, 3.0).lights[0].color;
  EXPECT_LT(low.b, 0.1f * low.r);
  EXPECT_GT(glm::length(daylightAt(given, 3.0).sky.zenith), 0.0f);  // dusk, not night
}

}  // namespace
}  // namespace sdfstream
